#pragma once

#include <deque>
#include <functional>
#include <map>
#include <optional>
#include <tuple>
#include <vector>

#include "core/score/calibration_frame.h"

namespace stcalib {

// Per-frame score vectors (one score per candidate calibration) kept from one call to the next.
// An online calibrator scores a window that slides or grows by one frame per call; as long as
// what the scores depend on besides the frame (`Setting`: the candidates, the map level, the
// score options; compared exactly with ==) stays the same, a frame scored by an earlier call is
// not scored again. A frame is known by its index, camera stamp and number of points, so a caller
// must not change a frame's content under the same key (the calibrator's frames are pruned once,
// when they arrive, and then const). Two frames with the same key in one window are each scored,
// never shared. Frames that left the window are forgotten.
template <typename Setting>
class FrameScoreCache {
 public:
  // Frames scored since construction (the work the cache did not save).
  int frames_scored() const { return frames_scored_; }

  // The score vector of each of `scorer`'s frames (a WindowScorer), in frame order: from the
  // cache, or `score_frame(f)`. The pointers are valid until the next call.
  template <typename Scorer>
  std::vector<const std::vector<double>*> FrameScores(
      const Scorer& scorer, Setting setting,
      const std::function<std::vector<double>(size_t f)>& score_frame) {
    if (!setting_ || !(*setting_ == setting)) {
      scores_.clear();
      setting_ = std::move(setting);
    }
    std::map<FrameKey, std::vector<double>> kept;
    duplicates_.clear();
    std::vector<const std::vector<double>*> frame_scores;
    for (size_t f = 0; f < scorer.num_frames(); ++f) {
      const CalibrationFrame& frame = scorer.frame(f);
      const FrameKey key{frame.index, frame.camera_time_s, frame.size()};
      if (kept.count(key) > 0) {  // an earlier frame of this window took the key
        duplicates_.push_back(Score(score_frame, f));
        frame_scores.push_back(&duplicates_.back());
        continue;
      }
      auto it = scores_.find(key);
      std::vector<double> scores =
          it != scores_.end() ? std::move(it->second) : Score(score_frame, f);
      frame_scores.push_back(&kept.emplace(key, std::move(scores)).first->second);
    }
    scores_ = std::move(kept);  // std::map nodes keep their addresses when moved
    return frame_scores;
  }

 private:
  struct FrameKey {
    int index;
    double camera_time_s;
    size_t points;
    bool operator<(const FrameKey& o) const {
      return std::tie(index, camera_time_s, points) < std::tie(o.index, o.camera_time_s, o.points);
    }
  };
  std::vector<double> Score(const std::function<std::vector<double>(size_t)>& score_frame,
                            size_t f) {
    ++frames_scored_;
    return score_frame(f);
  }

  std::optional<Setting> setting_;  // what the kept scores belong to; none before the first call
  std::map<FrameKey, std::vector<double>> scores_;
  std::deque<std::vector<double>> duplicates_;
  int frames_scored_ = 0;
};

}  // namespace stcalib
