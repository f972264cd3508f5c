#include "core/online/acquisition.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "core/types/transform.h"

namespace stcalib {

Dominance JudgeDominance(const std::vector<std::vector<double>>& frame_scores,
                         const std::vector<CalibrationState>& states, int shared_sweep_frames,
                         const DominanceOptions& options) {
  CHECK_EQ(frame_scores.size(), states.size());
  Dominance out;
  out.rivals.resize(states.size());
  if (states.empty()) {
    out.detail = "no hypothesis";
    return out;
  }
  out.frames = static_cast<int>(frame_scores[0].size());
  for (const std::vector<double>& scores : frame_scores) {
    CHECK_EQ(static_cast<int>(scores.size()), out.frames) << "JudgeDominance: unequal frames";
  }
  std::vector<double> sums(states.size(), 0.0);
  for (size_t k = 0; k < states.size(); ++k) {
    for (double s : frame_scores[k]) sums[k] += s;
  }
  out.best = static_cast<int>(std::max_element(sums.begin(), sums.end()) - sums.begin());
  const CalibrationState& best = states[out.best];
  const int n = out.frames;
  // Frames sharing a sweep through their local maps are one observation, not several.
  const double effective_n =
      std::max(1.0, static_cast<double>(n) / std::max(1, shared_sweep_frames));
  // Each frame's gains relative to that frame's scale (the mean |score| of the hypotheses on it):
  // frames with many edges score higher and would otherwise weigh more in the spread.
  std::vector<double> scale(n, 0.0);
  for (int f = 0; f < n; ++f) {
    for (const std::vector<double>& scores : frame_scores) scale[f] += std::abs(scores[f]);
    scale[f] = std::max(scale[f] / states.size(), 1e-9);
  }
  int standing = 0;
  for (size_t k = 0; k < states.size(); ++k) {
    if (static_cast<int>(k) == out.best) continue;
    RivalMargin& rival = out.rivals[k];
    rival.rotation_deg =
        RotationErrorDeg(states[k].T_camera_lidar.linear(), best.T_camera_lidar.linear());
    rival.time_offset_s = states[k].time_offset_s - best.time_offset_s;
    rival.score_share =
        sums[out.best] != 0 ? (sums[out.best] - sums[k]) / std::abs(sums[out.best]) : 0.0;
    rival.merged = rival.rotation_deg < options.merge_deg;
    double mean = 0, square = 0;
    for (int f = 0; f < n; ++f) mean += (frame_scores[out.best][f] - frame_scores[k][f]) / scale[f];
    mean /= std::max(1, n);
    for (int f = 0; f < n; ++f) {
      const double d = (frame_scores[out.best][f] - frame_scores[k][f]) / scale[f] - mean;
      square += d * d;
    }
    const double sd = n > 1 ? std::sqrt(square / (n - 1)) : 0.0;
    const double standard_error = sd / std::sqrt(effective_n);
    rival.t_statistic = standard_error > 0 ? mean / standard_error
                        : mean > 0         ? std::numeric_limits<double>::infinity()
                                           : 0.0;
    if (!rival.merged && rival.t_statistic < options.min_t) ++standing;
  }
  char text[160];
  if (n < options.min_frames) {
    std::snprintf(text, sizeof(text), "%d frames seen, %d needed", n, options.min_frames);
    out.detail = text;
    return out;
  }
  out.dominant = standing == 0;
  std::snprintf(text, sizeof(text), "over %d frames, %d rival(s) within %.1f standard errors", n,
                standing, options.min_t);
  out.detail = text;
  return out;
}

std::string DescribeRivals(const Dominance& dominance) {
  std::string out;
  for (size_t k = 0; k < dominance.rivals.size(); ++k) {
    if (static_cast<int>(k) == dominance.best) continue;
    const RivalMargin& r = dominance.rivals[k];
    char line[160];
    std::snprintf(line, sizeof(line),
                  "%s%.2f deg and %+.1f ms from the best, %.1f %% lower, %.1f SE%s",
                  out.empty() ? "" : "; ", r.rotation_deg, 1000 * r.time_offset_s,
                  100 * r.score_share, r.t_statistic, r.merged ? " (same peak)" : "");
    out += line;
  }
  return out;
}

Status Acquisition::Centre(const CalibrationState& centre,
                           const std::vector<const CalibrationFrame*>& frames,
                           double horizontal_weight, const StartUncertainty& span) {
  STCALIB_RETURN_IF_ERROR(HypothesisLattice::Create(centre, span, LatticeSteps(), &lattice_));
  window_.Clear();
  hypotheses_.clear();
  dominance_ = Dominance();
  for (const CalibrationFrame* frame : frames) AddFrame(*frame, horizontal_weight);
  return Status::Ok();
}

void Acquisition::AddFrame(const CalibrationFrame& frame, double horizontal_weight) {
  CHECK(centred());
  std::vector<float> scores = window_.TakeSpare();
  ScoreFrameOnLattice(frame, lattice_, horizontal_weight, kLatticePoints, &scores);
  window_.Add(frame.index, std::move(scores));
}

const std::vector<Hypothesis>& Acquisition::Update(WindowScorer* search, WindowScorer* judge,
                                                   const CalibrationState& incumbent,
                                                   const CalibrationState& anchor,
                                                   const AdaptiveGridSearchOptions& options,
                                                   int shared_sweep_frames, int* evaluations) {
  CHECK(centred());
  const std::vector<size_t> top = TopHypotheses(lattice_, window_.sums(), kHypotheses);
  // Refinement on the fine maps: rotation and δ (the lattice's translation stays; the estimate's
  // own search moves it), from the state a hypothesis of the same lattice rotation had.
  AdaptiveGridSearchOptions refine = options;
  refine.search_translation = false;
  std::vector<Hypothesis> next;
  for (size_t k = 0; k <= top.size(); ++k) {
    // A lattice point outside the search's bounds (the lattice reaches half a step past the
    // span) could win and never be taken.
    Hypothesis hypothesis;
    if (k == top.size()) {  // the estimate, as one hypothesis among the others
      hypothesis.incumbent = true;
      hypothesis.state = incumbent;
    } else {
      const size_t h = top[k];
      hypothesis.state = lattice_.State(h);
      if (!WithinBounds(hypothesis.state, anchor, options)) continue;
      hypothesis.lattice_index = h;
      hypothesis.lattice_score = window_.sums()[h];
      // The peaks' rotations are distinct: at most one carried hypothesis matches.
      for (const Hypothesis& carried : hypotheses_) {
        if (!carried.incumbent &&
            lattice_.RotationOf(carried.lattice_index) == lattice_.RotationOf(h)) {
          hypothesis.state = carried.state;
          break;
        }
      }
    }
    const SearchResult result = AdaptiveGridSearch(search, hypothesis.state, anchor, refine);
    *evaluations += result.evaluations;
    hypothesis.state = result.state;
    for (size_t f = 0; f < judge->num_frames(); ++f) {
      hypothesis.frame_scores.push_back(judge->EvaluateFrame(f, hypothesis.state, -1).score);
    }
    *evaluations += static_cast<int>(judge->num_frames());
    if (VLOG_IS_ON(2) && !hypothesis.incumbent) {
      const size_t h = hypothesis.lattice_index;
      double fine = 0;
      for (double v : hypothesis.frame_scores) fine += v;
      const Eigen::Vector3d r = lattice_.RotationOffsetRad(h) * 180 / M_PI;
      const Eigen::Vector3d t = lattice_.TranslationOffsetM(h);
      LOG(INFO) << "hypothesis cell r(" << r.transpose() << ") t(" << t.transpose() << ") dt "
                << lattice_.TimeOffsetOffsetS(h) << " lattice " << hypothesis.lattice_score
                << " fine " << fine << " moved "
                << RotationErrorDeg(lattice_.State(h).T_camera_lidar.linear(),
                                    hypothesis.state.T_camera_lidar.linear());
    }
    next.push_back(std::move(hypothesis));
  }
  std::vector<std::vector<double>> scores;
  std::vector<CalibrationState> states;
  for (const Hypothesis& h : next) {
    scores.push_back(h.frame_scores);
    states.push_back(h.state);
  }
  // A refinement window shorter than DominanceOptions::min_frames is all there is to compare on.
  DominanceOptions dominance;
  dominance.min_frames = std::max(2, std::min(dominance.min_frames, max_frames_));
  dominance_ = JudgeDominance(scores, states, shared_sweep_frames, dominance);
  // Best first (the dominance's best leads; the rivals keep their order and their margins).
  if (dominance_.best > 0) {
    std::swap(next[0], next[dominance_.best]);
    std::swap(dominance_.rivals[0], dominance_.rivals[dominance_.best]);
    dominance_.best = 0;
  }
  hypotheses_ = std::move(next);
  return hypotheses_;
}

double Acquisition::LeadOverIncumbent() const {
  for (size_t k = 0; k < hypotheses_.size(); ++k) {
    if (!hypotheses_[k].incumbent) continue;
    if (static_cast<int>(k) == dominance_.best || dominance_.rivals[k].merged) return 0;
    return dominance_.rivals[k].t_statistic;
  }
  return 0;
}

}  // namespace stcalib
