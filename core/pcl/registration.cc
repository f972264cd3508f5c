#include "core/pcl/registration.h"

#include <pcl/filters/voxel_grid.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/icp.h>
#include <pcl/registration/ndt.h>

namespace stcalib {
namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

Cloud::Ptr ToCloud(const std::vector<Eigen::Vector3d>& points, double voxel_m) {
  Cloud::Ptr cloud(new Cloud);
  cloud->reserve(points.size());
  for (const auto& p : points) cloud->emplace_back(p.x(), p.y(), p.z());
  if (voxel_m <= 0) return cloud;
  Cloud::Ptr filtered(new Cloud);
  pcl::VoxelGrid<pcl::PointXYZ> grid;
  grid.setInputCloud(cloud);
  grid.setLeafSize(voxel_m, voxel_m, voxel_m);
  grid.filter(*filtered);
  return filtered;
}

Rigid3d ToRigid(const Eigen::Matrix4f& m) {
  Rigid3d T = Rigid3d::Identity();
  T.matrix() = m.cast<double>();
  // Re-orthonormalise the single-precision rotation.
  T.linear() = Eigen::Quaterniond(T.linear()).normalized().toRotationMatrix();
  return T;
}

Status CheckInput(const std::vector<Eigen::Vector3d>& source,
                  const std::vector<Eigen::Vector3d>& target, const char* what) {
  if (source.size() < 10 || target.size() < 10) {
    return Status::Error(std::string(what) + ": too few points to register (" +
                         std::to_string(source.size()) + " source, " +
                         std::to_string(target.size()) + " target)");
  }
  return Status::Ok();
}

}  // namespace

Status RegisterNdt(const std::vector<Eigen::Vector3d>& source,
                   const std::vector<Eigen::Vector3d>& target, const Rigid3d& initial,
                   const NdtOptions& options, RegistrationResult* result) {
  STCALIB_RETURN_IF_ERROR(CheckInput(source, target, "NDT"));
  pcl::NormalDistributionsTransform<pcl::PointXYZ, pcl::PointXYZ> ndt;
  ndt.setResolution(static_cast<float>(options.resolution_m));
  ndt.setStepSize(options.step_size_m);
  ndt.setTransformationEpsilon(options.epsilon);
  ndt.setMaximumIterations(options.max_iterations);
  ndt.setInputSource(ToCloud(source, options.voxel_m));
  ndt.setInputTarget(ToCloud(target, options.voxel_m));
  Cloud aligned;
  ndt.align(aligned, initial.matrix().cast<float>());
  result->T_target_source = ToRigid(ndt.getFinalTransformation());
  result->iterations = ndt.getFinalNumIteration();
  result->converged = ndt.hasConverged();
  result->fitness = ndt.getFitnessScore();
  return Status::Ok();
}

Status RegisterIcp(const std::vector<Eigen::Vector3d>& source,
                   const std::vector<Eigen::Vector3d>& target, const Rigid3d& initial,
                   const IcpOptions& options, RegistrationResult* result) {
  STCALIB_RETURN_IF_ERROR(CheckInput(source, target, "ICP"));
  pcl::IterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> icp;
  icp.setMaxCorrespondenceDistance(options.max_correspondence_m);
  icp.setMaximumIterations(options.max_iterations);
  icp.setInputSource(ToCloud(source, options.voxel_m));
  icp.setInputTarget(ToCloud(target, options.voxel_m));
  Cloud aligned;
  icp.align(aligned, initial.matrix().cast<float>());
  result->T_target_source = ToRigid(icp.getFinalTransformation());
  result->iterations = options.max_iterations;
  result->converged = icp.hasConverged();
  result->fitness = icp.getFitnessScore(options.max_correspondence_m);
  return Status::Ok();
}

}  // namespace stcalib
