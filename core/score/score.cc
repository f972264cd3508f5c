#include "core/score/score.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace stcalib {
namespace {

// A CV_32F map with its limits as doubles (converted once, not per sample).
struct MapView {
  explicit MapView(const cv::Mat& map)
      : data(map.ptr<float>(0)),
        step(map.step1()),
        cols(map.cols),
        rows(map.rows),
        last_col(map.cols - 1),
        last_row(map.rows - 1) {
    CHECK_EQ(map.type(), CV_32F);
  }
  const float* data;
  size_t step;  // floats per row
  double cols, rows, last_col, last_row;
};

// Bilinear sample of a map; 0 outside.
inline float Sample(const MapView& map, double u, double v) {
  if (!(u >= 0 && v >= 0 && u < map.last_col && v < map.last_row)) return 0.0f;
  const int u0 = static_cast<int>(u), v0 = static_cast<int>(v);
  const float fu = static_cast<float>(u - u0), fv = static_cast<float>(v - v0);
  const float* row0 = map.data + v0 * map.step;
  const float* row1 = row0 + map.step;
  return (1 - fv) * ((1 - fu) * row0[u0] + fu * row0[u0 + 1]) +
         fv * ((1 - fu) * row1[u0] + fu * row1[u0 + 1]);
}

// One point's share of a score: the map at its pixel (u, v), weighted, and whether it landed in
// the image.
inline void AddSample(double u, double v, const MapView& map, float w, double* score,
                      int* projected) {
  const float s = Sample(map, u, v);
  if (u >= 0 && v >= 0 && u < map.cols && v < map.rows) ++*projected;
  *score += w * s;
}

// The same at the projection of h = K·R_rect·p_camera + p4.
inline void AddProjection(const Eigen::Vector3d& h, const MapView& map, float w,
                          ScoreValue* value) {
  AddSample(h.x() / h.z(), h.y() / h.z(), map, w, &value->score, &value->projected);
}

// A LiDAR point p (at its sweep's stamp) of a frame under a calibration, in one affine map:
// h = K·R_rect·(R·(Rv·p + tv) + t) + p4 = M·p + b, and depth = depth_row·p + depth_offset, with
// Tv = (Rv, tv) the motion model over e0 + δ.
struct FrameProjection {
  Eigen::Matrix3d M;
  Eigen::Vector3d b;
  Eigen::Vector3d depth_row;
  double depth_offset;
};
FrameProjection ProjectionOf(const CalibrationFrame& cf, const Eigen::Matrix3d& R,
                             const Eigen::Vector3d& t, const Rigid3d& Tv) {
  const Eigen::Matrix3d KR = cf.camera.P_rect.leftCols<3>() * cf.camera.R_rect_00;
  const Eigen::Matrix3d R_total = R * Tv.linear();
  const Eigen::Vector3d t_total = R * Tv.translation() + t;
  FrameProjection p;
  p.M = KR * R_total;
  p.b = KR * t_total + cf.camera.P_rect.col(3);
  p.depth_row = (cf.camera.R_rect_00.row(2) * R_total).transpose();
  p.depth_offset = cf.camera.R_rect_00.row(2).dot(t_total);
  return p;
}

// The score map of edge kind `kind` at `level` (negative counts from the finest: −1).
const cv::Mat& ScoreMapAt(const CalibrationFrame& cf, int kind, int level) {
  const int maps = static_cast<int>(cf.score_maps[kind].size());
  const int l = level < 0 ? maps + level : level;
  CHECK(l >= 0 && l < maps) << "score level " << level << " of " << maps;
  return cf.score_maps[kind][l];
}

}  // namespace

const std::vector<Eigen::Matrix<double, 6, 1>>& NeighbourDirections(bool translation) {
  static const std::vector<Eigen::Matrix<double, 6, 1>> all = [] {
    std::vector<Eigen::Matrix<double, 6, 1>> d;
    for (int code = 0; code < 729; ++code) {
      if (code == 364) continue;  // the centre
      Eigen::Matrix<double, 6, 1> v;
      int c = code;
      for (int k = 0; k < 6; ++k) {
        v[k] = c % 3 - 1;
        c /= 3;
      }
      d.push_back(v);
    }
    return d;
  }();
  static const std::vector<Eigen::Matrix<double, 6, 1>> rotation_only = [] {
    std::vector<Eigen::Matrix<double, 6, 1>> d;
    for (const auto& v : all) {
      if (v.tail<3>().isZero()) d.push_back(v);
    }
    return d;
  }();
  return translation ? all : rotation_only;
}

CalibrationState Step(const CalibrationState& state, const Eigen::Vector3d& rotation_rad,
                      const Eigen::Vector3d& translation_m, double time_offset_s) {
  CalibrationState out = state;
  out.T_camera_lidar.linear() = state.T_camera_lidar.linear() * ExpSO3(rotation_rad);
  out.T_camera_lidar.translation() += translation_m;
  out.time_offset_s += time_offset_s;
  return out;
}

WindowScorer::WindowScorer(std::vector<const CalibrationFrame*> frames, const ScoreOptions& options)
    : frames_(std::move(frames)), options_(options) {
  for (const CalibrationFrame* f : frames_) {
    CHECK(f != nullptr);
    std::vector<int> selected;
    const size_t n = f->size();
    const size_t keep =
        options.max_points_per_frame > 0 ? std::min<size_t>(n, options.max_points_per_frame) : n;
    for (size_t k = 0; k < keep; ++k) selected.push_back(static_cast<int>(k * n / keep));
    std::vector<float> weights;
    std::vector<uint8_t> kinds;
    for (int i : selected) {
      kinds.push_back(static_cast<uint8_t>(f->kinds[i]));
      weights.push_back(static_cast<float>(f->kinds[i] == EdgeKind::kHorizontal
                                               ? options.horizontal_weight
                                               : 1.0 - options.horizontal_weight));
    }
    std::vector<Eigen::Vector3d> points;
    points.reserve(selected.size());
    for (int i : selected) points.push_back(f->points_lidar[i]);
    weights_.push_back(std::move(weights));
    kinds_.push_back(std::move(kinds));
    points_.push_back(std::move(points));
  }
}

int WindowScorer::num_levels() const {
  int levels = std::numeric_limits<int>::max();
  for (const CalibrationFrame* f : frames_) {
    levels = std::min<int>(levels, std::min(f->score_maps[0].size(), f->score_maps[1].size()));
  }
  return frames_.empty() ? 0 : levels;
}

ScoreValue WindowScorer::EvaluateLevel(const CalibrationState& state, int level, size_t begin,
                                       size_t end) {
  return EvaluateOn(
      state,
      [level](const CalibrationFrame& cf, int kind) -> const cv::Mat& {
        return ScoreMapAt(cf, kind, level);
      },
      begin, end);
}

ScoreValue WindowScorer::Evaluate(const CalibrationState& state, int level) {
  return EvaluateLevel(state, level, 0, frames_.size());
}

ScoreValue WindowScorer::EvaluateFrame(size_t f, const CalibrationState& state, int level) {
  CHECK_LT(f, frames_.size());
  return EvaluateLevel(state, level, f, f + 1);
}

double WindowScorer::GrayRate(const CalibrationState& state) {
  // A frame that keeps no plain IDT has it made from its distance map (PlainIdt). A scorer over
  // a few frames (the search window, whose search reads the gray rate at every step) keeps what
  // it made; one over more frames (the refinement's, read once or twice) makes each frame's in
  // turn and drops it, or its maps would add as much memory as the frames hold themselves.
  constexpr size_t kMaxFramesKeepingPlainIdt = 4;
  const bool keep = frames_.size() <= kMaxFramesKeepingPlainIdt;
  if (keep) plain_idt_.resize(frames_.size());
  std::array<cv::Mat, 2> scratch;
  const CalibrationFrame* scratch_frame = nullptr;
  return EvaluateOn(
             state,
             [&](const CalibrationFrame& cf, int kind) -> const cv::Mat& {
               if (!cf.gray_map[kind].empty()) return cf.gray_map[kind];
               if (!(cf.gray_basin_px > 0)) return cf.score_maps[kind].back();
               std::array<cv::Mat, 2>* maps = &scratch;
               if (keep) {
                 const size_t f = std::find(frames_.begin(), frames_.end(), &cf) - frames_.begin();
                 maps = &plain_idt_[f];
               } else if (scratch_frame != &cf) {  // the previous frame's maps are done with
                 scratch = {};
                 scratch_frame = &cf;
               }
               if ((*maps)[kind].empty()) (*maps)[kind] = PlainIdt(cf, kind);
               return (*maps)[kind];
             },
             0, frames_.size())
      .gray_rate;
}

template <typename MapOf>
ScoreValue WindowScorer::EvaluateOn(const CalibrationState& state, const MapOf& map_of,
                                    size_t begin, size_t end) {
  ScoreValue value;
  double weight_sum = 0;
  for (size_t f = begin; f < end; ++f) {
    const CalibrationFrame& cf = *frames_[f];
    const MapView maps[2] = {MapView(map_of(cf, 0)), MapView(map_of(cf, 1))};
    const std::vector<Eigen::Vector3d>& points = points_[f];
    const FrameProjection p =
        ProjectionOf(cf, state.T_camera_lidar.linear(), state.T_camera_lidar.translation(),
                     LidarMotion(cf.twist, cf.e0_s + state.time_offset_s));
    for (size_t k = 0; k < points.size(); ++k) {
      const float w = weights_[f][k];
      weight_sum += w;
      if (p.depth_row.dot(points[k]) + p.depth_offset < cf.camera.min_depth_m) continue;
      const Eigen::Vector3d h = p.M * points[k] + p.b;
      AddProjection(h, maps[kinds_[f][k]], w, &value);
    }
  }
  value.gray_rate = weight_sum > 0 ? value.score / 255.0 / weight_sum : 0.0;
  value.weight_sum = weight_sum;
  return value;
}

std::vector<ScoreValue> WindowScorer::EvaluateStates(const std::vector<CalibrationState>& states,
                                                     int level) {
  return EvaluateStatesOn(states, level, 0, frames_.size());
}

std::vector<ScoreValue> WindowScorer::EvaluateStatesOnFrame(
    size_t f, const std::vector<CalibrationState>& states, int level) {
  CHECK_LT(f, frames_.size());
  return EvaluateStatesOn(states, level, f, f + 1);
}

std::vector<ScoreValue> WindowScorer::EvaluateStatesOn(const std::vector<CalibrationState>& states,
                                                       int level, size_t begin, size_t end) {
  std::vector<ScoreValue> values(states.size());
  if (states.empty()) return values;
  // Grouped by their rotation (equal matrices share the projection products).
  std::vector<std::vector<size_t>> groups;
  for (size_t n = 0; n < states.size(); ++n) {
    CHECK_EQ(states[n].time_offset_s, states[0].time_offset_s) << "EvaluateStates: one δ";
    size_t g = 0;
    while (g < groups.size() && !(states[groups[g].front()].T_camera_lidar.linear() ==
                                  states[n].T_camera_lidar.linear())) {
      ++g;
    }
    if (g == groups.size()) groups.emplace_back();
    groups[g].push_back(n);
  }
  // Each group's translations as arrays (b = K·R_rect·t + p4 and the depth offset), laid out
  // group after group, so that the projection of a point under all of a group's translations is
  // one vectorised loop.
  std::vector<size_t> lane_begin(groups.size() + 1, 0);
  for (size_t g = 0; g < groups.size(); ++g) lane_begin[g + 1] = lane_begin[g] + groups[g].size();
  const size_t lanes = lane_begin.back();
  std::vector<double> bx(lanes), by(lanes), bz(lanes), depth_offset(lanes), u(lanes), v(lanes);
  std::vector<uint8_t> in_front(lanes);
  // Per lane, its state's sums (ScoreValue::score, ::projected), point by point in order.
  std::vector<double> score(lanes, 0.0);
  std::vector<int> projected(lanes, 0);
  std::vector<Eigen::Matrix3d> M(groups.size());
  std::vector<Eigen::Vector3d> depth_row(groups.size());
  double weight_sum = 0;
  for (size_t f = begin; f < end; ++f) {
    const CalibrationFrame& cf = *frames_[f];
    const MapView maps[2] = {MapView(ScoreMapAt(cf, 0, level)), MapView(ScoreMapAt(cf, 1, level))};
    const std::vector<Eigen::Vector3d>& points = points_[f];
    for (size_t k = 0; k < points.size(); ++k) weight_sum += weights_[f][k];
    // As EvaluateOn: h = M·p + b, depth = depth_row·p + depth_offset.
    const Rigid3d Tv = LidarMotion(cf.twist, cf.e0_s + states[0].time_offset_s);
    for (size_t g = 0; g < groups.size(); ++g) {
      const Eigen::Matrix3d& R = states[groups[g].front()].T_camera_lidar.linear();
      for (size_t j = 0; j < groups[g].size(); ++j) {
        const FrameProjection p =
            ProjectionOf(cf, R, states[groups[g][j]].T_camera_lidar.translation(), Tv);
        if (j == 0) {
          M[g] = p.M;
          depth_row[g] = p.depth_row;
        }
        const size_t lane = lane_begin[g] + j;
        bx[lane] = p.b.x();
        by[lane] = p.b.y();
        bz[lane] = p.b.z();
        depth_offset[lane] = p.depth_offset;
      }
    }
    const double min_depth_m = cf.camera.min_depth_m;
    // Point by point, every state: one point's samples under all the states lie within a few
    // pixels of each other, so they stay in the cache (state by state, every point, they were
    // fetched again for each rotation). Each state still sums its points in order.
    for (size_t k = 0; k < points.size(); ++k) {
      const float w = weights_[f][k];
      const MapView& map = maps[kinds_[f][k]];
      for (size_t g = 0; g < groups.size(); ++g) {
        const double depth = depth_row[g].dot(points[k]);
        const Eigen::Vector3d Mp = M[g] * points[k];
        const double mx = Mp.x(), my = Mp.y(), mz = Mp.z();
        const size_t first = lane_begin[g], m = groups[g].size();
        // Unaliased lanes, so that the divisions vectorise (each is still one IEEE division).
        const double* __restrict gbx = bx.data() + first;
        const double* __restrict gby = by.data() + first;
        const double* __restrict gbz = bz.data() + first;
        const double* __restrict gdepth = depth_offset.data() + first;
        double* __restrict gu = u.data() + first;
        double* __restrict gv = v.data() + first;
        uint8_t* __restrict gfront = in_front.data() + first;
        for (size_t j = 0; j < m; ++j) {
          const double hz = mz + gbz[j];
          gu[j] = (mx + gbx[j]) / hz;
          gv[j] = (my + gby[j]) / hz;
        }
        for (size_t j = 0; j < m; ++j) gfront[j] = !(depth + gdepth[j] < min_depth_m);
        double* __restrict gscore = score.data() + first;
        int* __restrict gprojected = projected.data() + first;
        for (size_t j = 0; j < m; ++j) {
          if (gfront[j]) AddSample(gu[j], gv[j], map, w, &gscore[j], &gprojected[j]);
        }
      }
    }
  }
  for (size_t g = 0; g < groups.size(); ++g) {
    for (size_t j = 0; j < groups[g].size(); ++j) {
      values[groups[g][j]].score = score[lane_begin[g] + j];
      values[groups[g][j]].projected = projected[lane_begin[g] + j];
    }
  }
  for (ScoreValue& value : values) {
    value.gray_rate = weight_sum > 0 ? value.score / 255.0 / weight_sum : 0.0;
    value.weight_sum = weight_sum;
  }
  return values;
}

namespace {

// `frame` with the points for which `keep(i)` holds, their per-point entries kept with them.
template <typename Keep>
std::shared_ptr<const CalibrationFrame> KeepPoints(const CalibrationFrame& frame, Keep keep) {
  CHECK(frame.PointFieldsConsistent());
  std::vector<size_t> indices;
  indices.reserve(frame.size());
  for (size_t i = 0; i < frame.size(); ++i) {
    if (keep(i)) indices.push_back(i);
  }
  return std::make_shared<const CalibrationFrame>(frame.WithPoints(indices));
}

}  // namespace

std::shared_ptr<const CalibrationFrame> PruneToImage(const CalibrationFrame& frame,
                                                     const CalibrationState& state, double margin) {
  const double mu = margin * frame.camera.width;
  const double mv = margin * frame.camera.height;
  return KeepPoints(frame, [&](size_t i) {
    Eigen::Vector2d pixel;
    if (!ProjectFramePoint(frame, state, i, &pixel)) return false;
    return !(pixel.x() < mu || pixel.y() < mv || pixel.x() > frame.camera.width - mu ||
             pixel.y() > frame.camera.height - mv);
  });
}

std::shared_ptr<const CalibrationFrame> WithoutFolds(
    std::shared_ptr<const CalibrationFrame> frame) {
  CHECK(frame != nullptr);
  if (std::find(frame->folds.begin(), frame->folds.end(), 1) == frame->folds.end()) return frame;
  return KeepPoints(*frame, [&](size_t i) { return frame->folds[i] == 0; });
}

std::shared_ptr<const CalibrationFrame> LatestSweepsOnly(
    std::shared_ptr<const CalibrationFrame> frame, int sweeps) {
  CHECK(frame != nullptr);
  auto old = [&](uint8_t age) { return static_cast<int>(age) >= sweeps; };
  if (sweeps <= 0 || std::none_of(frame->sweep_ages.begin(), frame->sweep_ages.end(), old)) {
    return frame;
  }
  return KeepPoints(*frame, [&](size_t i) { return !old(frame->sweep_ages[i]); });
}

bool HealthSetting::operator==(const HealthSetting& o) const {
  return T_camera_lidar == o.T_camera_lidar && time_offset_s == o.time_offset_s &&
         rotation_deg == o.rotation_deg && translation_m == o.translation_m &&
         horizontal_weight == o.horizontal_weight && max_points_per_frame == o.max_points_per_frame;
}

double HealthScore(WindowScorer* scorer, const CalibrationState& state, double rotation_deg,
                   double translation_m, double* best_gain, HealthScoreCache* cache) {
  const double r = rotation_deg * M_PI / 180.0;
  // The centre first, then its neighbours, all scored in one pass per frame (EvaluateStates
  // equals Evaluate bit for bit). Window scores are sums over the frames in frame order, cached
  // or not.
  std::vector<CalibrationState> states = {state};
  for (const Eigen::Matrix<double, 6, 1>& d : NeighbourDirections(true)) {
    states.push_back(Step(state, r * d.head<3>(), translation_m * d.tail<3>(), 0.0));
  }
  HealthScoreCache local;
  const std::vector<const std::vector<double>*> frames =
      (cache != nullptr ? cache : &local)
          ->FrameScores(
              *scorer,
              {state.T_camera_lidar.matrix(), state.time_offset_s, rotation_deg, translation_m,
               scorer->options().horizontal_weight, scorer->options().max_points_per_frame},
              [&](size_t f) {
                std::vector<double> scores;
                for (const ScoreValue& v : scorer->EvaluateStatesOnFrame(f, states, -1)) {
                  scores.push_back(v.score);
                }
                return scores;
              });
  std::vector<double> window(states.size(), 0.0);
  for (const std::vector<double>* frame : frames) {
    for (size_t i = 0; i < window.size(); ++i) window[i] += (*frame)[i];
  }
  const double centre = window[0];
  double best = -std::numeric_limits<double>::infinity();
  int worse = 0;
  for (size_t n = 1; n < window.size(); ++n) {
    worse += window[n] < centre;
    best = std::max(best, window[n]);
  }
  if (best_gain != nullptr) *best_gain = centre > 0 ? best / centre - 1.0 : 0.0;
  return static_cast<double>(worse) / (states.size() - 1);
}

}  // namespace stcalib
