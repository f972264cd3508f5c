#include "core/search/adaptive_grid_search.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>

namespace stcalib {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

}  // namespace

Status AdaptiveGridSearchOptions::Validate() const {
  if (!(alpha1_rotation_deg > 0 && alpha2_translation_m > 0 && alpha3_rotation_deg > 0 &&
        alpha4_translation_m > 0)) {
    return Status::Error("search: step sizes must be > 0");
  }
  if (!(gamma >= 0 && gamma <= 1)) return Status::Error("search: gamma must be in [0, 1]");
  if (max_iterations < 1 || max_follow_steps < 0)
    return Status::Error("search: bad iteration caps");
  if (!(translation_prior_sigma_m > 0) || translation_prior_weight < 0 ||
      !(time_offset_prior_sigma_s > 0)) {
    return Status::Error("search: translation prior sigma must be > 0, weight >= 0");
  }
  if (!(time_offset_step_s > 0) || !(time_offset_bound_s >= 0)) {
    return Status::Error("search: time offset step must be > 0 and the bound >= 0");
  }
  return Status::Ok();
}

bool WithinBounds(const CalibrationState& state, const CalibrationState& anchor,
                  const AdaptiveGridSearchOptions& options) {
  return RotationErrorDeg(state.T_camera_lidar.linear(), anchor.T_camera_lidar.linear()) <=
             options.max_rotation_offset_deg &&
         (state.T_camera_lidar.translation() - anchor.T_camera_lidar.translation()).norm() <=
             options.max_translation_offset_m &&
         std::abs(state.time_offset_s) <= options.time_offset_bound_s + 1e-12;
}

SearchResult AdaptiveGridSearch(WindowScorer* scorer, const CalibrationState& start,
                                const CalibrationState& anchor,
                                const AdaptiveGridSearchOptions& options) {
  CHECK(options.Validate().ok()) << options.Validate().message();
  // The objective: the score with the translation prior.
  auto objective_of = [&](const CalibrationState& state, const ScoreValue& v) {
    const double z =
        (state.T_camera_lidar.translation() - anchor.T_camera_lidar.translation()).norm() /
        options.translation_prior_sigma_m;
    const double zt =
        (state.time_offset_s - anchor.time_offset_s) / options.time_offset_prior_sigma_s;
    return v.score - options.translation_prior_weight * 255.0 * v.weight_sum * (z * z + zt * zt);
  };
  auto objective = [&](const CalibrationState& state, int level) {
    return objective_of(state, scorer->Evaluate(state, level));
  };
  SearchResult result;
  result.state = start;
  result.start = scorer->Evaluate(start, -1);
  // The finest score map (the frames' last).
  const int level = std::max(scorer->num_levels() - 1, 0);
  {
    const auto& directions = NeighbourDirections(options.search_translation);
    const bool search_time = options.search_time_offset;
    CalibrationState& state = result.state;
    double current = objective(state, level);
    ++result.evaluations;
    bool large = scorer->GrayRate(state) < options.gamma;
    for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
      const double rot =
          (large ? options.alpha1_rotation_deg : options.alpha3_rotation_deg) * kDegToRad;
      const double trans = large ? options.alpha2_translation_m : options.alpha4_translation_m;
      double best = current;
      Eigen::Matrix<double, 6, 1> best_dir = Eigen::Matrix<double, 6, 1>::Zero();
      // The neighbours within the bounds, scored in one pass.
      std::vector<CalibrationState> candidates;
      std::vector<size_t> direction_of;
      for (size_t n = 0; n < directions.size(); ++n) {
        const Eigen::Matrix<double, 6, 1>& d = directions[n];
        CalibrationState candidate = Step(state, rot * d.head<3>(), trans * d.tail<3>(), 0.0);
        if (!WithinBounds(candidate, anchor, options)) continue;
        candidates.push_back(std::move(candidate));
        direction_of.push_back(n);
      }
      const std::vector<ScoreValue> values = scorer->EvaluateStates(candidates, level);
      for (size_t c = 0; c < candidates.size(); ++c) {
        const double s = objective_of(candidates[c], values[c]);
        if (s > best) {
          best = s;
          best_dir = directions[direction_of[c]];
        }
      }
      result.evaluations += directions.size();
      bool moved = false;
      if (best > current) {
        // Steepest-direction following.
        state = Step(state, rot * best_dir.head<3>(), trans * best_dir.tail<3>(), 0.0);
        current = best;
        ++result.moves;
        moved = true;
        for (int k = 0; k < options.max_follow_steps; ++k) {
          const CalibrationState next =
              Step(state, rot * best_dir.head<3>(), trans * best_dir.tail<3>(), 0.0);
          if (!WithinBounds(next, anchor, options)) break;
          const double s = objective(next, level);
          ++result.evaluations;
          if (s <= current) break;
          state = next;
          current = s;
          ++result.moves;
        }
      }
      if (search_time) {
        // 1-D δ search interleaved with the 6-DoF steps.
        const double step = options.time_offset_step_s * (large ? 2.0 : 1.0);
        for (double sign : {-1.0, 1.0}) {
          for (int k = 1; k <= 3; ++k) {
            const double delta = state.time_offset_s + sign * k * step;
            if (std::abs(delta) > options.time_offset_bound_s) break;
            CalibrationState candidate = state;
            candidate.time_offset_s = delta;
            const double s = objective(candidate, level);
            ++result.evaluations;
            if (s > current) {
              state = candidate;
              current = s;
              moved = true;
            }
          }
        }
      }
      if (!moved) {
        if (large) {
          large = false;  // adapt: refine with the small pair before stopping
          continue;
        }
        break;
      }
      // Re-choose the pair from the gray rate on the finest map.
      large = large && scorer->GrayRate(state) < options.gamma;
    }
  }
  result.end = scorer->Evaluate(result.state, -1);
  return result;
}

namespace {

// Best and second local maximum (at least min_separation away) of a 1-D score profile.
struct PeakStats {
  size_t best = 0;
  size_t second = 0;
  double ratio = 0;  // (second − floor) / (best − floor)
};
PeakStats FindPeaks(const std::vector<double>& offsets, const std::vector<double>& scores,
                    double min_separation) {
  PeakStats stats;
  if (scores.empty()) return stats;
  stats.best = std::max_element(scores.begin(), scores.end()) - scores.begin();
  const double floor = *std::min_element(scores.begin(), scores.end());
  double second = floor;
  for (size_t i = 0; i < scores.size(); ++i) {
    const bool peak = (i == 0 || scores[i] >= scores[i - 1]) &&
                      (i + 1 == scores.size() || scores[i] >= scores[i + 1]);
    if (!peak || std::abs(offsets[i] - offsets[stats.best]) < min_separation) continue;
    if (scores[i] > second) {
      second = scores[i];
      stats.second = i;
    }
  }
  const double range = scores[stats.best] - floor;
  stats.ratio = range > 0 ? (second - floor) / range : 0.0;
  return stats;
}

}  // namespace

TimeOffsetProfile ProfileTimeOffset(WindowScorer* scorer, const CalibrationState& state,
                                    double bound_s, double step_s, double ratio,
                                    double min_separation_s) {
  TimeOffsetProfile profile;
  for (double d = -bound_s; d <= bound_s + 1e-12; d += step_s) {
    CalibrationState s = state;
    s.time_offset_s = d;
    profile.offsets_s.push_back(d);
    profile.scores.push_back(scorer->Evaluate(s, -1).score);
  }
  if (profile.scores.empty()) return profile;
  const PeakStats peaks = FindPeaks(profile.offsets_s, profile.scores, min_separation_s);
  profile.best_s = profile.offsets_s[peaks.best];
  profile.second_peak_s = profile.offsets_s[peaks.second];
  profile.second_peak_ratio = peaks.ratio;
  profile.alias_suspect = profile.second_peak_ratio >= ratio;
  return profile;
}

RotationAxisProfile ProfileRotationAxis(WindowScorer* scorer, const CalibrationState& state,
                                        int axis, double half_range_deg, double step_deg,
                                        double ratio, double min_separation_deg, int level) {
  CHECK(axis >= 0 && axis < 3) << "rotation axis " << axis;
  RotationAxisProfile profile;
  for (double d = -half_range_deg; d <= half_range_deg + 1e-9; d += step_deg) {
    Eigen::Vector3d r = Eigen::Vector3d::Zero();
    r[axis] = d * M_PI / 180.0;
    profile.offsets_deg.push_back(d);
    profile.scores.push_back(
        scorer->Evaluate(Step(state, r, Eigen::Vector3d::Zero(), 0.0), level).score);
  }
  if (profile.scores.empty()) return profile;
  const PeakStats peaks = FindPeaks(profile.offsets_deg, profile.scores, min_separation_deg);
  profile.best_deg = profile.offsets_deg[peaks.best];
  profile.second_peak_deg = profile.offsets_deg[peaks.second];
  profile.second_peak_ratio = peaks.ratio;
  profile.ambiguous = profile.second_peak_ratio >= ratio;
  return profile;
}

}  // namespace stcalib
