#pragma once

#include <future>
#include <memory>
#include <vector>

#include "core/online/frame_source.h"
#include "core/score/calibration_frame.h"
#include "core/types/status.h"

namespace stcalib {

// Loads a drive's frames first..last (every camera's: DriveFrameSource::LoadCameras) in order on a
// second thread, one frame ahead of the caller: reading and decoding the next frame (image, sweep,
// image and LiDAR features, local map) runs while the caller calibrates the current one, as a live
// camera and LiDAR deliver theirs. The calibration stays on the caller's thread. The loader thread
// is the only user of `source` from construction until the last frame was returned or the
// prefetcher is destroyed (which waits for a load in flight). Frames do not depend on the
// calibration, so the results are those of loading in the caller's thread.
class FramePrefetcher {
 public:
  struct Loaded {
    int index = 0;
    std::vector<CameraFrameLoad> cameras;  ///< DriveFrameSource::LoadCameras's, one per camera
  };

  FramePrefetcher(DriveFrameSource* source, int first, int last);
  ~FramePrefetcher();
  FramePrefetcher(const FramePrefetcher&) = delete;
  FramePrefetcher& operator=(const FramePrefetcher&) = delete;

  // The next frame in order (waiting for its load), and the load of the one after it started;
  // false once every frame was returned.
  bool Next(Loaded* out);

 private:
  void Start(int index);

  DriveFrameSource* source_;
  int next_, last_;
  std::future<Loaded> pending_;
};

}  // namespace stcalib
