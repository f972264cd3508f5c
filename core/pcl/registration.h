#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/types/status.h"
#include "core/types/transform.h"

namespace stcalib {

// Scan registration with PCL, behind an Eigen-only interface: PCL headers stay in
// registration.cc, the one translation unit that pays their compile time.
struct NdtOptions {
  double resolution_m = 1.0;  ///< NDT cell size [m]
  double step_size_m = 0.1;   ///< More–Thuente maximum step [m]
  double epsilon = 1e-6;      ///< PCL transformation epsilon (compared with a squared step)
  int max_iterations = 35;
  double voxel_m = 0.4;  ///< both clouds are voxel-downsampled first [m]; 0 = no
};

struct IcpOptions {
  double max_correspondence_m = 1.0;
  int max_iterations = 5;
  double voxel_m = 0.4;
};

struct RegistrationResult {
  Rigid3d T_target_source = Rigid3d::Identity();
  int iterations = 0;
  bool converged = false;
  double fitness = 0;  ///< mean squared distance of corresponding points [m²] (PCL's score)
};

Status RegisterNdt(const std::vector<Eigen::Vector3d>& source,
                   const std::vector<Eigen::Vector3d>& target,
                   const Rigid3d& initial_T_target_source, const NdtOptions& options,
                   RegistrationResult* result);

Status RegisterIcp(const std::vector<Eigen::Vector3d>& source,
                   const std::vector<Eigen::Vector3d>& target,
                   const Rigid3d& initial_T_target_source, const IcpOptions& options,
                   RegistrationResult* result);

}  // namespace stcalib
