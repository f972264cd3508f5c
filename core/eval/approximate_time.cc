#include "core/eval/approximate_time.h"

#include <glog/logging.h>

#include <algorithm>
#include <cstdlib>

namespace stcalib {

ApproximateTimeSynchronizer::ApproximateTimeSynchronizer(int num_topics, size_t queue_size)
    : queues_(num_topics), queue_size_(queue_size) {
  CHECK_GE(num_topics, 2);
  CHECK_GE(queue_size, 1u);
}

bool ApproximateTimeSynchronizer::TryPublish(std::vector<int>* set) {
  for (const auto& q : queues_) {
    if (q.empty()) return false;
  }
  // Pivot: the topic whose oldest message is the latest.
  size_t pivot = 0;
  for (size_t t = 1; t < queues_.size(); ++t) {
    if (queues_[t].front().stamp > queues_[pivot].front().stamp) pivot = t;
  }
  const StampNs pivot_stamp = queues_[pivot].front().stamp;
  // Every other topic must have a message at or after the pivot: then the best match for the
  // pivot is known (later messages are farther).
  std::vector<size_t> choice(queues_.size(), 0);
  for (size_t t = 0; t < queues_.size(); ++t) {
    if (t == pivot) continue;
    const auto& q = queues_[t];
    if (q.back().stamp < pivot_stamp) return false;
    size_t best = 0;
    for (size_t k = 1; k < q.size(); ++k) {
      if (std::llabs(q[k].stamp - pivot_stamp) < std::llabs(q[best].stamp - pivot_stamp)) best = k;
    }
    choice[t] = best;
  }
  set->assign(queues_.size(), -1);
  for (size_t t = 0; t < queues_.size(); ++t) {
    (*set)[t] = queues_[t][choice[t]].index;
    // Drop the chosen message and everything older.
    queues_[t].erase(queues_[t].begin(), queues_[t].begin() + choice[t] + 1);
  }
  return true;
}

std::vector<std::vector<int>> ApproximateTimeSynchronizer::Add(int topic, int index,
                                                               StampNs stamp_ns) {
  CHECK(topic >= 0 && topic < static_cast<int>(queues_.size()));
  auto& q = queues_[topic];
  q.push_back({index, stamp_ns});
  if (q.size() > queue_size_) q.pop_front();  // a full queue drops its oldest message
  std::vector<std::vector<int>> published;
  std::vector<int> set;
  while (TryPublish(&set)) published.push_back(set);
  return published;
}

std::vector<std::pair<int, int>> PairApproximateTime(const std::vector<StampNs>& a,
                                                     const std::vector<StampNs>& b) {
  ApproximateTimeSynchronizer sync(2);
  std::vector<std::pair<int, int>> pairs;
  size_t i = 0, j = 0;
  while (i < a.size() || j < b.size()) {
    const bool take_a = j >= b.size() || (i < a.size() && a[i] <= b[j]);
    const auto sets =
        take_a ? sync.Add(0, static_cast<int>(i), a[i]) : sync.Add(1, static_cast<int>(j), b[j]);
    if (take_a)
      ++i;
    else
      ++j;
    for (const auto& s : sets) pairs.emplace_back(s[0], s[1]);
  }
  return pairs;
}

}  // namespace stcalib
