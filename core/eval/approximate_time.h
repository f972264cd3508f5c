#pragma once

#include <deque>
#include <vector>

#include "core/io/timestamps.h"

namespace stcalib {

// The pairing ROS message_filters' ApproximateTime policy produces, for N topics: one queue per
// topic; whenever every queue holds a message, the pivot is the latest of the queue fronts; once
// each other topic has a message at or after the pivot (so no later message can match it
// better), the set with the smallest stamp spread around the pivot is published and everything
// up to it is dropped. Each message is used at most once, sets come out in time order, and the
// output rate is bounded by the slowest topic.
class ApproximateTimeSynchronizer {
 public:
  explicit ApproximateTimeSynchronizer(int num_topics, size_t queue_size = 10);

  // Adds message `index` of `topic` (messages of a topic arrive in stamp order) and returns the
  // sets published as a result: one message index per topic.
  std::vector<std::vector<int>> Add(int topic, int index, StampNs stamp_ns);

 private:
  struct Message {
    int index;
    StampNs stamp;
  };
  bool TryPublish(std::vector<int>* set);

  std::vector<std::deque<Message>> queues_;
  size_t queue_size_;
};

// Feeds two stamped streams in arrival (stamp) order and returns the published pairs
// (index in `a`, index in `b`).
std::vector<std::pair<int, int>> PairApproximateTime(const std::vector<StampNs>& a,
                                                     const std::vector<StampNs>& b);

}  // namespace stcalib
