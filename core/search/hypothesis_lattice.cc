#include "core/search/hypothesis_lattice.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numeric>

#include "core/motion/motion_model.h"
#include "core/types/transform.h"

namespace stcalib {
namespace {

// Offsets k·step, |k| ≤ K with K·step + step/2 ≥ span: every offset within the span lies within
// half a step of one of them (only k = 0 when the span is under half a step).
std::vector<int> AxisCells(double span, double step) {
  const int half =
      step > 0 ? std::max(0, static_cast<int>(std::ceil(span / step - 0.5 - 1e-9))) : 0;
  std::vector<int> cells;
  for (int k = -half; k <= half; ++k) cells.push_back(k);
  return cells;
}

constexpr double kDegToRad = M_PI / 180.0;

}  // namespace

Status ParseStartUncertainty(const std::string& text, StartUncertainty* uncertainty) {
  const std::string what = "--init_uncertainty=" + text + ": ";
  std::vector<double> figures;
  size_t begin = 0;
  while (begin <= text.size()) {
    const size_t end = std::min(text.find(',', begin), text.size());
    const std::string field = text.substr(begin, end - begin);
    char* stop = nullptr;
    const double value = std::strtod(field.c_str(), &stop);
    if (field.empty() || stop != field.c_str() + field.size() || !std::isfinite(value) ||
        !(value > 0)) {
      return Status::Error(what + "\"" + field +
                           "\" is not a positive number (expected ROT_DEG,TRANS_M,TIME_S)");
    }
    figures.push_back(value);
    begin = end + 1;
  }
  if (figures.size() != 3) {
    return Status::Error(what + "expected three figures ROT_DEG,TRANS_M,TIME_S, got " +
                         std::to_string(figures.size()));
  }
  uncertainty->rotation_deg = figures[0];
  uncertainty->translation_m = figures[1];
  uncertainty->time_offset_s = figures[2];
  return Status::Ok();
}

std::string StartUncertaintyText(const StartUncertainty& uncertainty) {
  char text[96];
  std::snprintf(text, sizeof(text), "%g,%g,%g", uncertainty.rotation_deg, uncertainty.translation_m,
                uncertainty.time_offset_s);
  return text;
}

size_t HypothesisLattice::CountFor(const StartUncertainty& span, const LatticeSteps& steps) {
  double count = AxisCells(span.time_offset_s, steps.time_offset_s).size();
  for (int k = 0; k < 3; ++k) {
    count *= AxisCells(span.rotation_deg, steps.rotation_deg[k]).size();
    count *= AxisCells(span.translation_m, steps.translation_m[k]).size();
  }
  return count > 1e15 ? static_cast<size_t>(1e15) : static_cast<size_t>(count);
}

Status HypothesisLattice::CheckFits(const StartUncertainty& span, const LatticeSteps& steps,
                                    size_t max_hypotheses) {
  const size_t count = CountFor(span, steps);
  if (count <= max_hypotheses) return Status::Ok();
  return Status::Error("a lattice of " + std::to_string(count) +
                       " hypotheses does not fit in memory (at most " +
                       std::to_string(max_hypotheses) + "): narrow the start uncertainty");
}

Status HypothesisLattice::Create(const CalibrationState& centre, const StartUncertainty& span,
                                 const LatticeSteps& steps, HypothesisLattice* lattice,
                                 size_t max_hypotheses) {
  STCALIB_RETURN_IF_ERROR(CheckFits(span, steps, max_hypotheses));
  HypothesisLattice out;
  out.centre_ = centre;
  out.steps_ = steps;
  std::vector<int> r[3], t[3];
  for (int k = 0; k < 3; ++k) {
    r[k] = AxisCells(span.rotation_deg, steps.rotation_deg[k]);
    t[k] = AxisCells(span.translation_m, steps.translation_m[k]);
  }
  for (int a : r[0]) {
    for (int b : r[1]) {
      for (int c : r[2]) {
        out.rotation_cells_.emplace_back(a, b, c);
        out.rotations_.push_back(Eigen::Vector3d(a, b, c).cwiseProduct(steps.rotation_deg) *
                                 kDegToRad);
      }
    }
  }
  for (int k : AxisCells(span.time_offset_s, steps.time_offset_s)) {
    out.time_offsets_s_.push_back(k * steps.time_offset_s);
  }
  for (int a : t[0]) {
    for (int b : t[1]) {
      for (int c : t[2]) {
        out.translations_.push_back(Eigen::Vector3d(a, b, c).cwiseProduct(steps.translation_m));
      }
    }
  }
  *lattice = std::move(out);
  return Status::Ok();
}

CalibrationState HypothesisLattice::State(size_t h) const {
  CHECK_LT(h, size());
  CalibrationState state = centre_;
  state.T_camera_lidar.linear() = ExpSO3(RotationOffsetRad(h)) * centre_.T_camera_lidar.linear();
  state.T_camera_lidar.translation() += TranslationOffsetM(h);
  state.time_offset_s += TimeOffsetOffsetS(h);
  return state;
}

namespace {

// Adds, for one rotation and δ, the score at every translation: for point i (camera-projective
// coordinates y0, y1, y2 before the translation's b = M·t + p4), the padded coarse map's cell at
// ((y0 + b0) / (y2 + b2), (y1 + b1) / (y2 + b2)) / scale + cell_offset (rounded down: the
// nearest cell, padding included), weighted. Points from `begin` to `end`
// read `map` (one edge kind). Written for the compiler to vectorise over points (gathers under
// AVX2 and AVX-512, which the clones select at run time).
// Under AddressSanitizer the clones' run-time resolver would run before the sanitizer's start-up:
// one portable version there.
#if defined(__SANITIZE_ADDRESS__)
#define STCALIB_VECTOR_CLONES
#else
#define STCALIB_VECTOR_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#endif
STCALIB_VECTOR_CLONES void AccumulateTranslations(const float* y0, const float* y1, const float* y2,
                                                  const float* weight, int begin, int end,
                                                  const float* b, int num_translations,
                                                  const float* map, int map_cols, int map_rows,
                                                  float inv_scale, float cell_offset,
                                                  float min_depth, float* out) {
  const float max_x = static_cast<float>(map_cols - 1);
  const float max_y = static_cast<float>(map_rows - 1);
  for (int c = 0; c < num_translations; ++c) {
    const float b0 = b[3 * c], b1 = b[3 * c + 1], b2 = b[3 * c + 2];
    float sum = 0.0f;
#pragma omp simd reduction(+ : sum)
    for (int i = begin; i < end; ++i) {
      const float z = y2[i] + b2;
      const float inv = inv_scale / std::max(z, 1e-3f);
      // Padded map: cell 0 and the last are zero; anything outside lands there.
      const float u = std::min(std::max((y0[i] + b0) * inv + cell_offset, 0.0f), max_x);
      const float v = std::min(std::max((y1[i] + b1) * inv + cell_offset, 0.0f), max_y);
      const int cell = static_cast<int>(v) * map_cols + static_cast<int>(u);
      // The cell is always inside the padded map: load, then mask (no branch in the loop).
      const float in_front = z >= min_depth ? 1.0f : 0.0f;
      sum += weight[i] * in_front * map[cell];
    }
    out[c] += sum;
  }
}

}  // namespace

void ScoreFrameOnLattice(const CalibrationFrame& frame, const HypothesisLattice& lattice,
                         double horizontal_weight, int max_points, std::vector<float>* scores) {
  scores->assign(lattice.size(), 0.0f);
  const int scale = frame.coarse_map_scale;
  if (frame.coarse_map[0].empty() || frame.coarse_map[1].empty() || scale <= 0 ||
      frame.kinds.size() != frame.size()) {
    return;
  }
  // Evenly thinned points, vertical ones first (each kind reads its own map).
  const size_t n = frame.size();
  const size_t keep = max_points > 0 ? std::min<size_t>(n, max_points) : n;
  std::vector<size_t> order[2];
  for (size_t k = 0; k < keep; ++k) {
    const size_t i = k * n / keep;
    order[frame.kinds[i] == EdgeKind::kHorizontal ? 1 : 0].push_back(i);
  }
  const int num_vertical = static_cast<int>(order[0].size());
  const int num_points = num_vertical + static_cast<int>(order[1].size());
  std::vector<float> weight(num_points);
  for (int k = 0; k < num_points; ++k) {
    weight[k] = static_cast<float>(k < num_vertical ? 1.0 - horizontal_weight : horizontal_weight);
  }
  const CameraModel& camera = frame.camera;
  const Eigen::Matrix3d M = camera.P_rect.leftCols<3>() * camera.R_rect_00;
  const Eigen::Vector3d p4 = camera.P_rect.col(3);
  const CalibrationState& centre = lattice.centre();
  // Per translation: b = M·(t_centre + Δt) + p4; the depth row of M·R_rect is that of P's third
  // row (rectified z plus P's small offset), so h_z ≥ min_depth stands in for the depth test.
  const size_t num_t = lattice.num_translations();
  std::vector<float> b(3 * num_t);
  for (size_t c = 0; c < num_t; ++c) {
    const Eigen::Vector3d bc =
        M * (centre.T_camera_lidar.translation() + lattice.TranslationOffsetM(c)) + p4;
    for (int k = 0; k < 3; ++k) b[3 * c + k] = static_cast<float>(bc[k]);
  }
  const size_t num_d = lattice.num_time_offsets();
  const size_t num_r = lattice.num_rotations();
  // The points carried by the motion model over e0 + δ, one set per δ of the lattice.
  std::vector<Eigen::Vector3f> moved(num_d * num_points);  // in float once, read per rotation
  for (size_t d = 0; d < num_d; ++d) {
    const double e = frame.e0_s + centre.time_offset_s + lattice.TimeOffsetOffsetS(d * num_t);
    const Rigid3d Tv = LidarMotion(frame.twist, e);
    for (int k = 0; k < num_points; ++k) {
      const size_t i = k < num_vertical ? order[0][k] : order[1][k - num_vertical];
      moved[d * num_points + k] = (Tv * frame.points_lidar[i]).cast<float>();
    }
  }
  const cv::Mat& map_v = frame.coarse_map[0];
  const cv::Mat& map_h = frame.coarse_map[1];
  CHECK(map_v.isContinuous() && map_h.isContinuous() && map_v.type() == CV_32F &&
        map_v.size() == map_h.size());
  const float inv_scale = 1.0f / static_cast<float>(scale);
  // A cell averages `scale` pixels: cell j's centre is pixel j·scale + (scale − 1)/2; +1 for the
  // padding and +1/2 to round to the nearest.
  const float cell_offset = 1.5f - 0.5f * (scale - 1) / scale;
  const float min_depth = static_cast<float>(camera.min_depth_m);
  std::vector<float> y0(num_points), y1(num_points), y2(num_points);
  for (size_t r = 0; r < num_r; ++r) {
    const size_t h_r = r * num_d * num_t;
    const Eigen::Matrix3f A =
        (M * ExpSO3(lattice.RotationOffsetRad(h_r)) * centre.T_camera_lidar.linear()).cast<float>();
    for (size_t d = 0; d < num_d; ++d) {
      const Eigen::Vector3f* X = &moved[d * num_points];
      for (int k = 0; k < num_points; ++k) {
        const Eigen::Vector3f& x = X[k];
        y0[k] = A.row(0).dot(x);
        y1[k] = A.row(1).dot(x);
        y2[k] = A.row(2).dot(x);
      }
      float* out = scores->data() + h_r + d * num_t;
      AccumulateTranslations(y0.data(), y1.data(), y2.data(), weight.data(), 0, num_vertical,
                             b.data(), static_cast<int>(num_t), map_v.ptr<float>(), map_v.cols,
                             map_v.rows, inv_scale, cell_offset, min_depth, out);
      AccumulateTranslations(y0.data(), y1.data(), y2.data(), weight.data(), num_vertical,
                             num_points, b.data(), static_cast<int>(num_t), map_h.ptr<float>(),
                             map_h.cols, map_h.rows, inv_scale, cell_offset, min_depth, out);
    }
  }
}

void LatticeWindow::Add(int frame_index, std::vector<float> scores) {
  if (sums_.size() != scores.size()) {
    CHECK(frames_.empty()) << "LatticeWindow: a score vector of another lattice";
    sums_.assign(scores.size(), 0.0);
  }
  for (size_t h = 0; h < scores.size(); ++h) sums_[h] += scores[h];
  frames_.emplace_back(frame_index, std::move(scores));
  while (static_cast<int>(frames_.size()) > max_frames_) {
    const std::vector<float>& old = frames_.front().second;
    for (size_t h = 0; h < old.size(); ++h) sums_[h] -= old[h];
    spare_ = std::move(frames_.front().second);
    frames_.pop_front();
  }
}

void LatticeWindow::Clear() {
  frames_.clear();
  sums_.clear();
  spare_.clear();
}

std::vector<int> LatticeWindow::FrameIndices() const {
  std::vector<int> indices;
  for (const auto& frame : frames_) indices.push_back(frame.first);
  return indices;
}

std::vector<size_t> TopHypotheses(const HypothesisLattice& lattice, const std::vector<double>& sums,
                                  int count, int min_separation_cells) {
  CHECK_EQ(sums.size(), lattice.size());
  const size_t per_rotation = lattice.num_time_offsets() * lattice.num_translations();
  std::vector<size_t> best(lattice.num_rotations());
  for (size_t r = 0; r < best.size(); ++r) {
    const auto begin = sums.begin() + r * per_rotation;
    best[r] = r * per_rotation + (std::max_element(begin, begin + per_rotation) - begin);
  }
  std::vector<size_t> order(best.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return sums[best[a]] > sums[best[b]] || (sums[best[a]] == sums[best[b]] && a < b);
  });
  std::vector<size_t> top;
  for (size_t r : order) {
    if (static_cast<int>(top.size()) >= count) break;
    bool separate = true;
    for (size_t h : top) {
      const Eigen::Vector3i gap =
          lattice.RotationCell(r) - lattice.RotationCell(lattice.RotationOf(h));
      if (gap.cwiseAbs().maxCoeff() < min_separation_cells) separate = false;
    }
    if (separate) top.push_back(best[r]);
  }
  return top;
}

}  // namespace stcalib
