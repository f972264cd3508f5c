#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/refine/refine.h"

namespace stcalib {

// How far the window's own data lets the rotation move (docs/method.md §7): neighbouring edge
// points of one edge are not independent measurements, so the refinement's covariance, which
// treats them as such, is optimistic. A jackknife over the window's frames measures the spread
// instead: each block of frames left out in turn, the rotation is refined again (translation and
// δ held), and the spread of those estimates gives each rotation axis its standard deviation.

// The jackknife standard deviation of `leave_one_out` (one estimate per frame left out, n ≥ 2):
// sqrt((n − 1) / n · Σ (θ_i − θ̄)²) per component; zero for fewer than 2.
Eigen::Vector3d JackknifeStd(const std::vector<Eigen::Vector3d>& leave_one_out);

struct RotationJackknife {
  int frames = 0;  ///< frames in the window (0: too few to leave one out, nothing measured)
  int blocks = 0;  ///< blocks of contiguous frames left out in turn
  // Per rotation axis (roll, pitch, yaw about the LiDAR axes, as kAxisNames) [deg].
  Eigen::Vector3d std_deg = Eigen::Vector3d::Zero();
  // Leave-one-out refinements that failed (they are left out of the spread).
  int failed = 0;
};

// The rotation's delete-a-block jackknife over `frames` (at least `min_frames` and two blocks,
// else nothing is measured): the frames are cut into n / block_frames contiguous blocks, each
// left out in turn (frames share sweeps through their local maps and scenery over seconds, so
// single frames are not independent), each refinement starting at `estimate` with the rotation
// prior there, and `mount_prior` for the held translation and δ. `options` as the calibrator
// refines (loss, weights); the translation and δ are held.
RotationJackknife JackknifeRotation(const std::vector<const CalibrationFrame*>& frames,
                                    const CalibrationState& estimate,
                                    const CalibrationState& mount_prior, RefineOptions options,
                                    int block_frames, int min_frames = 4);

}  // namespace stcalib
