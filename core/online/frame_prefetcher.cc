#include "core/online/frame_prefetcher.h"

#include <glog/logging.h>

namespace stcalib {

FramePrefetcher::FramePrefetcher(DriveFrameSource* source, int first, int last)
    : source_(source), next_(first), last_(last) {
  CHECK(source_ != nullptr);
  if (next_ <= last_) Start(next_);
}

FramePrefetcher::~FramePrefetcher() {
  if (pending_.valid()) pending_.wait();
}

void FramePrefetcher::Start(int index) {
  pending_ = std::async(std::launch::async, [source = source_, index]() {
    Loaded loaded;
    loaded.index = index;
    source->LoadCameras(static_cast<size_t>(index), &loaded.cameras);
    return loaded;
  });
}

bool FramePrefetcher::Next(Loaded* out) {
  if (next_ > last_) return false;
  *out = pending_.get();
  ++next_;
  if (next_ <= last_) Start(next_);
  return true;
}

}  // namespace stcalib
