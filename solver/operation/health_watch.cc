#include "solver/operation/health_watch.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include "solver/operation/calibration_variables.h"
#include "solver/operation/rest_evidence.h"
#include "solver/operation/rest_problem.h"

namespace cdpr {
namespace {

// Terms within this Akaike gain of the best look alike: diagnose's
// kMimicAicMargin (solver/diagnosis/diagnosis.h), the same judgement.
constexpr double kAlikeAicMargin = 4.0;
constexpr double kMassStepFraction = 1e-4;  // finite-difference step of the load column

struct Candidate {
  FaultTerm term;
  int cable;
  int first_column;
  int columns;
};

std::vector<Candidate> candidates() {
  std::vector<Candidate> out;
  for (int i = 0; i < kCableCount; ++i) out.push_back({FaultTerm::kEncoderOffset, i, i, 1});
  for (int i = 0; i < kCableCount; ++i) out.push_back({FaultTerm::kAnchor, i, 4 + 3 * i, 3});
  for (int i = 0; i < kCableCount; ++i) out.push_back({FaultTerm::kCableElongation, i, 16 + i, 1});
  out.push_back({FaultTerm::kLoad, -1, 20, 4});
  out.push_back({FaultTerm::kLoadCellBias, -1, 24, 1});
  return out;
}

// The statistic of column j: its term, cable and component.
TermStatistic statistic_of_column(int j) {
  TermStatistic s;
  if (j < 4) {
    s.term = FaultTerm::kEncoderOffset, s.cable = j;
  } else if (j < 16) {
    s.term = FaultTerm::kAnchor, s.cable = (j - 4) / 3, s.component = (j - 4) % 3;
  } else if (j < 20) {
    s.term = FaultTerm::kCableElongation, s.cable = j - 16;
  } else if (j < 24) {
    s.term = FaultTerm::kLoad, s.component = j - 20;
  } else {
    s.term = FaultTerm::kLoadCellBias;
  }
  return s;
}

constexpr int kBaseline = 16;  // the calibration's error: offsets (columns 0-3) and anchors (4-15)

// The linearised fit over the calibration's error beta (in every rest) and
// a candidate's change theta (after the onset): information H and score g
// over x = (beta, theta), from the rests before (only beta) and since.
struct Fit {
  Eigen::MatrixXd H;
  Eigen::VectorXd g;
};

Fit joint_fit(const Eigen::Matrix<double, kBaseline, kBaseline>& prior, const RestInformation& before,
              const RestInformation& since, const std::vector<int>& changed) {
  Fit f;
  const int columns = static_cast<int>(changed.size());
  const int n = kBaseline + columns;
  f.H = Eigen::MatrixXd::Zero(n, n);
  f.g = Eigen::VectorXd::Zero(n);
  f.H.topLeftCorner(kBaseline, kBaseline) = prior + before.information.topLeftCorner<kBaseline, kBaseline>() +
                                            since.information.topLeftCorner<kBaseline, kBaseline>();
  f.g.head(kBaseline) = before.score.head<kBaseline>() + since.score.head<kBaseline>();
  for (int a = 0; a < columns; ++a) {
    const int j = changed[a];
    f.H.block(0, kBaseline + a, kBaseline, 1) = since.information.block(0, j, kBaseline, 1);
    f.H.block(kBaseline + a, 0, 1, kBaseline) = since.information.block(j, 0, 1, kBaseline);
    for (int b = 0; b < columns; ++b) f.H(kBaseline + a, kBaseline + b) = since.information(j, changed[b]);
    f.g(kBaseline + a) = since.score(j);
  }
  return f;
}

std::vector<int> columns_of(const Candidate& c) {
  std::vector<int> out;
  for (int k = 0; k < c.columns; ++k) out.push_back(c.first_column + k);
  return out;
}

// The fit of one candidate: theta and its covariance from H^-1 g, its
// chi-square drop over the fit without it.
std::optional<TermEstimate> fit_candidate(const Candidate& c, const Eigen::Matrix<double, kBaseline, kBaseline>& prior,
                                          const RestInformation& before, const RestInformation& since) {
  const Fit with = joint_fit(prior, before, since, columns_of(c));
  const Fit without = joint_fit(prior, before, since, {});
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(with.H), ldlt0(without.H);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive() || !(ldlt.vectorD().minCoeff() > 1e-12 * with.H.trace()) ||
      ldlt0.info() != Eigen::Success) {
    return std::nullopt;
  }
  const Eigen::VectorXd x = ldlt.solve(with.g);
  const Eigen::MatrixXd covariance = ldlt.solve(Eigen::MatrixXd::Identity(with.H.rows(), with.H.cols()));
  TermEstimate e;
  e.term = c.term;
  e.cable = c.cable;
  e.value = x.tail(c.columns);
  e.sigma = covariance.bottomRightCorner(c.columns, c.columns).diagonal().cwiseSqrt();
  e.chi_square_drop = with.g.dot(x) - without.g.dot(ldlt0.solve(without.g));
  return e;
}

// What the rests since the onset tell of an anchor move beyond an offset
// change of the same cable: F, the information of the anchor's columns with
// the calibration's error and the offset change eliminated (a Schur
// complement of the joint fit over both).
std::optional<Eigen::Matrix3d> anchor_beyond_offset(const Eigen::Matrix<double, kBaseline, kBaseline>& prior,
                                                    const RestInformation& before, const RestInformation& since,
                                                    int cable) {
  const int anchor = 4 + 3 * cable;
  const Fit both = joint_fit(prior, before, since, {cable, anchor, anchor + 1, anchor + 2});
  const int rest = kBaseline + 1;
  const Eigen::LDLT<Eigen::MatrixXd> others(both.H.topLeftCorner(rest, rest));
  if (others.info() != Eigen::Success || !others.isPositive()) return std::nullopt;
  const Eigen::MatrixXd coupling = both.H.block(0, rest, rest, 3);
  return Eigen::Matrix3d(both.H.bottomRightCorner(3, 3) - coupling.transpose() * others.solve(coupling));
}

// x with P(chi-square, 3 degrees of freedom > x) = rate, by bisection of
// the closed form erfc(sqrt(x / 2)) + sqrt(2 x / pi) e^(-x / 2).
double chi_square_3_quantile_above(double rate) {
  const auto tail = [](double x) { return std::erfc(std::sqrt(x / 2.0)) + std::sqrt(2.0 * x / M_PI) * std::exp(-x / 2.0); };
  double low = 0.0, high = 200.0;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (low + high);
    (tail(mid) > rate ? low : high) = mid;
  }
  return 0.5 * (low + high);
}

}  // namespace

std::string fault_term_name(FaultTerm term, int cable) {
  const std::string i = std::to_string(cable);
  switch (term) {
    case FaultTerm::kEncoderOffset: return "offset[" + i + "]";
    case FaultTerm::kAnchor: return "anchor[" + i + "]";
    case FaultTerm::kCableElongation: return "encoder_scale[" + i + "]";
    case FaultTerm::kLoad: return "load";
    case FaultTerm::kLoadCellBias: return "load_cell_bias";
  }
  return "?";
}

std::string fault_term_meaning(FaultTerm term, int cable) {
  const std::string i = std::to_string(cable);
  switch (term) {
    case FaultTerm::kEncoderOffset: return "encoder offset slip of cable " + i;
    case FaultTerm::kAnchor: return "anchor " + i + " moved";
    case FaultTerm::kCableElongation: return "cable " + i + " elongation (creep)";
    case FaultTerm::kLoad: return "load or centre of mass changed (not a calibration fault)";
    case FaultTerm::kLoadCellBias: return "load-cell bias changed";
  }
  return "?";
}

HealthWatch::HealthWatch(Robot robot, Calibration calibration, HealthWatchOptions options)
    : robot_(std::move(robot)), calibration_(std::move(calibration)), options_(options) {
  heavier_ = robot_;
  heavier_.platform_mass_kg = robot_.platform_mass_kg * (1.0 + kMassStepFraction);
  if (!calibration_effects(calibration_, &unusable_)) {
    if (unusable_.empty()) unusable_ = "the calibration cannot be used";
  }
  const double force_sigma = robot_.noise.force_n;
  for (int j = 0; j < kFaultColumns; ++j) {
    const TermStatistic s = statistic_of_column(j);
    statistics_.push_back(s);
    switch (s.term) {
      case FaultTerm::kEncoderOffset: shifts_.push_back(options_.offset_shift_m); break;
      case FaultTerm::kAnchor: shifts_.push_back(options_.anchor_shift_m); break;
      case FaultTerm::kCableElongation: shifts_.push_back(options_.elongation_shift_m); break;
      case FaultTerm::kLoad:
        shifts_.push_back(s.component == 0 ? options_.mass_shift_fraction * robot_.platform_mass_kg
                                           : options_.com_shift_m);
        break;
      case FaultTerm::kLoadCellBias:
        shifts_.push_back(options_.force_bias_shift_n > 0.0 ? options_.force_bias_shift_n : 3.0 * force_sigma);
        break;
    }
  }
  // The calibration's error as a prior, in column order (offsets, then anchors).
  baseline_information_.setZero();
  if (options_.calibration_covariance) {
    Eigen::Matrix<double, kBaseline, kBaseline> permute = Eigen::Matrix<double, kBaseline, kBaseline>::Zero();
    for (int i = 0; i < kCableCount; ++i) {
      permute(i, 12 + i) = 1.0;  // offset i: covariance row 12 + i
      for (int a = 0; a < 3; ++a) permute(4 + 3 * i + a, 3 * i + a) = 1.0;
    }
    const Eigen::Matrix<double, kBaseline, kBaseline> covariance =
        permute * *options_.calibration_covariance * permute.transpose();
    baseline_information_ = covariance.inverse();
  } else if (static_cast<int>(calibration_.winches.size()) == kCableCount) {
    // A sigma of zero (unknown) counts as a tenth of a millimetre: held, not free.
    const auto information = [](double sigma) { return 1.0 / std::max(sigma * sigma, 1e-8); };
    for (int i = 0; i < kCableCount; ++i) {
      const WinchCalibration& w = calibration_.winches[i];
      baseline_information_(i, i) = information(w.offset_sigma_m);
      for (int a = 0; a < 3; ++a) baseline_information_(4 + 3 * i + a, 4 + 3 * i + a) = information(w.anchor_sigma(a));
    }
  }
  tracked_information_ = baseline_information_;
  anchor_margin_ = chi_square_3_quantile_above(std::clamp(options_.anchor_misnaming_rate, 1e-12, 1.0));
  // Siegmund: a one-sided CUSUM of Gaussian log likelihood ratios with
  // standardised shift delta crosses h, without change, after about
  // e^(h + 1.166 delta) / (delta^2 / 2) rests; Bonferroni over all of them.
  const double delta = options_.design_standardised_shift;
  const double statistics = 2.0 * kFaultColumns;
  threshold_ = std::log(statistics * options_.clean_rests_per_false_alarm * delta * delta / 2.0) - 1.166 * delta;
}

std::vector<Sample> HealthWatch::rests_since_onset() const {
  if (!finding_) return {};
  return std::vector<Sample>(rests_.begin() + finding_->since_rest, rests_.end());
}

RestCheck HealthWatch::add_rest(const Sample& rest) {
  RestCheck out;
  out.rest = static_cast<int>(rests_.size());
  out.sample_id = rest.id;
  out.threshold = threshold_;
  out.has_measured_pose = has_measured_pose(rest);
  rests_.push_back(rest);
  if (!unusable_.empty()) {
    out.why = unusable_;
    out.statistics = statistics_;
    return out;
  }
  if (reference_payout_m_ <= 0.0) {
    for (int i = 0; i < kCableCount; ++i) {
      reference_payout_m_ += (rest.encoder_m[i] - calibration_.winches[i].offset_m) / kCableCount;
    }
    if (!(reference_payout_m_ > 0.0)) reference_payout_m_ = 1.0;
  }

  const Pose start = last_pose_ ? *last_pose_ : nominal_start(calibration_, rest);
  std::string why;
  out.pose = localize_rest(robot_, calibration_, rest, start, options_.localize, &why);
  Pose check_start = start;
  Eigen::Vector2d check_force = Eigen::Vector2d::Zero();
  if (out.pose) {
    last_pose_ = out.pose->world_T_platform;
    check_start = out.pose->world_T_platform;
    check_force = out.pose->reference_force;
    if (out.has_measured_pose) {
      const Eigen::Matrix<double, 6, 1> d =
          pose_difference(Pose{rest.position_world, rest.world_R_platform}, out.pose->world_T_platform);
      out.pose_difference_sigma = d.cwiseQuotient(out.pose->covariance.diagonal().cwiseSqrt());
    }
  } else {
    out.why = "no pose from the cables: " + why;
    const std::optional<RestStart> fallback = rest_start(robot_, calibration_, rest, start, &why);
    if (!fallback) {
      out.statistics = statistics_;
      return out;
    }
    check_start = fallback->world_T_platform;
    check_force = fallback->reference_force;
  }

  RestEvidenceInputs in;
  in.robot = &robot_;
  in.heavier = &heavier_;
  in.mass_step_kg = heavier_.platform_mass_kg - robot_.platform_mass_kg;
  in.calibration = &calibration_;
  in.calibration_effects = *calibration_effects(calibration_, nullptr);
  in.height_sigma_m = options_.height_sigma_m;
  in.use_measured_pose = options_.use_measured_pose;
  in.reference_payout_m = reference_payout_m_;
  const std::optional<RestEvidence> evidence = rest_evidence(in, rest, check_start, check_force, out.rest, &why);
  if (!evidence) {
    out.why = (out.why.empty() ? "" : out.why + "; ") + why;
    out.statistics = statistics_;
    return out;
  }
  out.checked = true;
  out.encoder_residual_sigma = evidence->encoder_residual_sigma;
  out.force_residual_sigma = evidence->force_residual_sigma;
  information_.push_back(evidence->information);
  update_statistics(evidence->information, out);
  return out;
}

void HealthWatch::update_statistics(const RestInformation& info, RestCheck& out) {
  // The calibration's error beta as the statistics see it: mean and
  // covariance (zero and none when ignored).
  Eigen::Matrix<double, kBaseline, 1> error_mean = Eigen::Matrix<double, kBaseline, 1>::Zero();
  Eigen::Matrix<double, kBaseline, kBaseline> error_covariance = Eigen::Matrix<double, kBaseline, kBaseline>::Zero();
  if (options_.calibration_error != CalibrationErrorHandling::kIgnored) {
    const Eigen::LDLT<Eigen::Matrix<double, kBaseline, kBaseline>> ldlt(tracked_information_);
    if (ldlt.info() == Eigen::Success && ldlt.isPositive()) {
      error_covariance = ldlt.solve(Eigen::Matrix<double, kBaseline, kBaseline>::Identity());
      error_mean = ldlt.solve(tracked_score_);
    }
  }
  int crossing = -1;
  double highest = threshold_;
  for (int j = 0; j < kFaultColumns; ++j) {
    TermStatistic& s = statistics_[j];
    const double I = info.information(j, j);
    if (!(I > 1e-12)) {
      s.z = 0.0;
      s.standardised_shift = 0.0;
      continue;
    }
    // The innovation: the score less what the calibration's error predicts,
    // with its variance including that prediction's uncertainty.
    const Eigen::Matrix<double, 1, kBaseline> coupling = info.information.block<1, kBaseline>(j, 0);
    const double b = info.score(j) - coupling * error_mean;
    const double variance = I + coupling * error_covariance * coupling.transpose();
    const double theta = shifts_[j], shift = theta * I;  // the score's mean under a change theta
    s.z = b / std::sqrt(variance);
    s.standardised_shift = shift / std::sqrt(variance);
    const double drift = 0.5 * shift * shift / variance;
    // Page's CUSUM on the log likelihood ratio of +-theta against 0.
    const double up = std::max(0.0, s.cusum_up + shift * b / variance - drift);
    const double down = std::max(0.0, s.cusum_down - shift * b / variance - drift);
    if (s.cusum_up == 0.0 && up > 0.0) onset_up_[j] = info.rest;
    if (s.cusum_down == 0.0 && down > 0.0) onset_down_[j] = info.rest;
    s.cusum_up = up;
    s.cusum_down = down;
    s.onset_rest = up == 0.0 && down == 0.0 ? -1 : (up >= down ? onset_up_[j] : onset_down_[j]);
    if (std::max(up, down) > highest) {
      highest = std::max(up, down);
      crossing = j;
    }
  }
  out.statistics = statistics_;
  const int tracking = options_.calibration_error_rests;
  if (options_.calibration_error == CalibrationErrorHandling::kTracked && !finding_ &&
      (tracking <= 0 || tracked_rests_ < tracking)) {
    tracked_information_ += info.information.topLeftCorner<kBaseline, kBaseline>();
    tracked_score_ += info.score.head<kBaseline>();
    ++tracked_rests_;
  }
  if (!finding_ && crossing >= 0) {
    StaleFinding f;
    f.statistic = statistics_[crossing];
    f.since_rest = std::max(0, f.statistic.onset_rest);
    f.since_sample_id = rests_[f.since_rest].id;
    f.fired_at_rest = out.rest;
    f.fired_at_sample_id = out.sample_id;
    finding_ = f;
    out.fired = true;
  }
  if (finding_) attribute();
}

void HealthWatch::attribute() {
  StaleFinding& f = *finding_;
  RestInformation before, since;
  f.rests_fitted = 0;
  for (const RestInformation& info : information_) {
    RestInformation& sum = info.rest < f.since_rest ? before : since;
    sum.score += info.score;
    sum.information += info.information;
    if (info.rest >= f.since_rest) ++f.rests_fitted;
  }
  f.candidates.clear();
  for (const Candidate& c : candidates()) {
    if (std::optional<TermEstimate> e = fit_candidate(c, baseline_information_, before, since)) {
      f.candidates.push_back(*e);
    }
  }
  std::sort(f.candidates.begin(), f.candidates.end(),
            [](const TermEstimate& a, const TermEstimate& b) { return a.aic_gain() > b.aic_gain(); });
  f.alike.clear();
  if (f.candidates.empty()) return;
  f.term = f.candidates.front();
  // An elongation or an anchor move differs from an offset of the same
  // cable only through how the payout and the cable's direction vary over
  // the rests: either is named only when it explains them better by the
  // margin; otherwise the slip, the simpler and commoner fault.
  if (f.term.term == FaultTerm::kCableElongation || f.term.term == FaultTerm::kAnchor) {
    for (const TermEstimate& e : f.candidates) {
      const bool anchor_loses = f.term.term == FaultTerm::kAnchor &&
                                f.term.chi_square_drop - e.chi_square_drop <= anchor_margin_;
      const bool elongation_loses = f.term.term == FaultTerm::kCableElongation &&
                                    f.term.aic_gain() - e.aic_gain() <= kAlikeAicMargin;
      if (e.term == FaultTerm::kEncoderOffset && e.cable == f.term.cable && (anchor_loses || elongation_loses)) {
        f.term = e;
        break;
      }
    }
  }
  f.alike.clear();
  for (const TermEstimate& e : f.candidates) {
    const bool same = e.term == f.term.term && e.cable == f.term.cable;
    if (!same && f.candidates.front().aic_gain() - e.aic_gain() <= kAlikeAicMargin) f.alike.push_back(e);
  }
  f.anchor_or_offset = anchor_or_offset(before, since);
}

std::optional<AnchorOrOffset> HealthWatch::anchor_or_offset(const RestInformation& before,
                                                            const RestInformation& since) const {
  const StaleFinding& f = *finding_;
  if (f.term.term != FaultTerm::kAnchor && f.term.term != FaultTerm::kEncoderOffset) return std::nullopt;
  const TermEstimate *anchor = nullptr, *offset = nullptr;
  for (const TermEstimate& e : f.candidates) {
    if (e.cable != f.term.cable) continue;
    if (e.term == FaultTerm::kAnchor) anchor = &e;
    if (e.term == FaultTerm::kEncoderOffset) offset = &e;
  }
  const std::optional<Eigen::Matrix3d> beyond = anchor_beyond_offset(baseline_information_, before, since, f.term.cable);
  if (!anchor || !offset || !beyond) return std::nullopt;
  AnchorOrOffset out;
  out.cable = f.term.cable;
  out.log_likelihood_ratio = anchor->chi_square_drop - offset->chi_square_drop;
  out.margin = anchor_margin_;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(*beyond);
  const double best = eigen.eigenvalues().maxCoeff();
  out.best_sigma_m = best > 0.0 ? 1.0 / std::sqrt(best) : std::numeric_limits<double>::infinity();
  const Eigen::Vector3d move = anchor->value;
  out.fitted_move_sigmas = std::sqrt(std::max(0.0, move.dot(*beyond * move)));
  return out;
}

}  // namespace cdpr
