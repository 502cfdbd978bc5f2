#pragma once
// The health test: at every rest the robot makes in operation, is the
// committed calibration still right? (docs/operation.md)
//
// Per rest, the check fit: the rest's kineto-static factor (Eq. 14-16 coupled
// by the statics, Eq. 5-11) and, when the row has one, the prior of its
// measured (onboard) pose, solved for the pose and the reference force with
// the calibration held fixed. Its whitened residual r and, for every fault
// term j of the catalogue below, the whitened derivative g_j of r with
// respect to the term's parameter, projected off the rest's own pose and
// force (what a changed pose would absorb): g~_j. Under a right calibration
// the score s_j = g~_j^T r is N(0, I_j), I_j = |g~_j|^2.
//
// Sequential change test: a two-sided CUSUM per term (Page), on the log
// likelihood ratio of a shift of the designed size theta_j against none:
//   S+_j = max(0, S+_j + theta_j s_j - theta_j^2 I_j / 2),  S-_j the same for -theta_j.
// Threshold: for Gaussian increments Siegmund's approximation gives the
// mean run length of one side without change, ARL0 ~ e^(h + 1.166 delta) /
// (delta^2 / 2), delta = theta sqrt(I) the standardised shift (designed 1.5:
// a 2 cm slip seen through 10 mm encoders and the onboard pose). With
// M = 2 x 25 one-sided statistics, h = ln(M N delta^2 / 2) - 1.166 delta keeps
// the whole test at one false alarm per N clean rests (Bonferroni; default
// N = 1000: h = 9.19). Lorden's bound ARL0 >= e^h guarantees at least one
// per e^h / M = 196 rests whatever the increments; the terms of one cable are
// strongly correlated, so the real rate is lower than designed. A change of
// the designed size is flagged after about h / (theta_j^2 I_j / 2) rests.
//
// The committed calibration's own error beta (its anchors and offsets, off
// within their covariance P0) shifts every rest's scores by A_j,beta beta,
// the same error at every rest: a standing bias of the test (kIgnored, the
// default; the designed rate assumes it small against theta_j / 2). With
// kTracked the test runs on the innovations instead: beta estimated from the
// rests so far (information P0^-1 + sum A_beta,beta, score sum b_beta), each
// score less its prediction A_j,beta beta^ and normalised by its predictive
// variance V_j = I_j + A_j,beta P A_beta,j. Tracked over every rest the
// innovations are white (a Kalman filter's), so the designed rate holds
// exactly whatever the calibration's error, but a change of an offset or
// anchor is slowly learnt as calibration error; held after K rests it is
// not, and the rate holds up to the error left after K rests. kPredictive
// only widens V_j by P0. Measured (docs/operation.md): none of the three
// flags a slip sooner than kIgnored; the flags are limited by delta.
//
// When a statistic crosses h the calibration is stale. The rests since the
// crossing statistic last left zero (the change's onset) are refitted with
// each candidate term (linearised, the per-rest pose and force eliminated),
// the committed calibration's own error marginalised: its anchors and
// offsets may be off within their covariance, by the same amount before and
// after the onset, so the rests before it tell that error from the change.
// The chi-square drop against its parameter count by Akaike's criterion, as
// diagnose ranks terms (solver/diagnosis/diagnosis.h); the best names the
// finding, with its size and sigma; candidates within 4 (diagnose's
// kMimicAicMargin) of the best look alike and are listed. An elongation of a
// cable or a move of its anchor is named over that cable's offset slip only
// when it beats it by that margin: they differ only by how the payout and
// the cable's direction vary over the rests. For an anchor against an
// offset the margin is that of a likelihood-ratio test: the anchor is named
// when 2 ln LR = (its chi-square drop - the offset's) exceeds the
// chi-square (3 degrees of freedom) quantile of anchor_misnaming_rate
// (default 1 %: 11.34): under a slip 2 ln LR is at most the chi-square of
// adding the anchor to the offset, so at most that rate of slips are named
// anchor moves. The finding says how well the rests span the cable's
// directions (AnchorOrOffset): a move the rests cannot resolve beyond an
// offset change is "looks alike", never an anchor. The finding is
// re-estimated with every further rest.
//
// Term catalogue (the names of diagnose and of the calibration's keys):
//   offset[i]         encoder offset slip of cable i                 [m]
//   anchor[i]         anchor (pulley exit point) i moved             [m, world x y z]
//   encoder_scale[i]  cable i elongation / creep: reading = (1 + s) payout, in metres at the reference payout
//   load              load or centre of mass changed: platform mass [kg] and centre of mass [m, platform frame]
//   load_cell_bias    load-cell bias changed                         [N]
//
// Pure numerics: no I/O, no clocks. Not thread-safe; one watch per robot.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "solver/model/calibration.h"
#include "solver/model/robot.h"
#include "solver/model/sample.h"
#include "solver/operation/localize.h"

namespace cdpr {

enum class FaultTerm { kEncoderOffset, kAnchor, kCableElongation, kLoad, kLoadCellBias };

// The catalogue's name of a term: "offset[2]", "anchor[1]",
// "encoder_scale[0]", "load", "load_cell_bias"; and its meaning in words.
std::string fault_term_name(FaultTerm term, int cable);
std::string fault_term_meaning(FaultTerm term, int cable);

// How the sequential test treats the committed calibration's own error.
enum class CalibrationErrorHandling {
  kIgnored,     // the scores as they come: the error is a standing bias of the statistics
  kPredictive,  // each score normalised by its variance including the calibration's covariance
  kTracked,     // the error estimated from the rests so far; the test runs on the innovations
};

struct HealthWatchOptions {
  LocalizeOptions localize;  // the pose from the cables reported per rest (its max_chi_square applies to it alone)
  double height_sigma_m = 1e-2;  // Eq. (15), as the calibration's fit
  // Weight the onboard pose where a row has one (the strongest evidence).
  bool use_measured_pose = true;
  // Designed false-alarm rate: at most one per this many clean rests, the whole test.
  double clean_rests_per_false_alarm = 1e3;
  // The standardised shift delta = theta sqrt(I) the threshold is designed for.
  double design_standardised_shift = 1.5;
  // Designed shifts (theta_j): the smallest changes worth flagging.
  double offset_shift_m = 0.02;
  double anchor_shift_m = 0.03;       // per world axis
  double elongation_shift_m = 0.02;   // at the reference payout
  double mass_shift_fraction = 0.05;  // of the platform mass
  double com_shift_m = 0.02;
  double force_bias_shift_n = 0.0;    // 0: 3 x the load cell's sigma
  // The calibration's joint covariance of anchors and offsets
  // (calibration_covariance.h); without it, its per-axis sigmas.
  std::optional<Eigen::Matrix<double, 4 * kCableCount, 4 * kCableCount>> calibration_covariance;
  // What the statistics make of the committed calibration's own error
  // (its anchors and offsets off within their covariance, the same at every
  // rest); see the header comment and docs/operation.md.
  CalibrationErrorHandling calibration_error = CalibrationErrorHandling::kIgnored;
  // kTracked: the error is re-estimated over this many checked rests, then
  // held; 0: over every rest, which keeps the innovations white.
  int calibration_error_rests = 0;
  // An anchor is named over its cable's offset when 2 ln LR exceeds the
  // chi-square (3 degrees of freedom) quantile of this rate: at most this
  // fraction of offset slips are named anchor moves (AnchorOrOffset).
  double anchor_misnaming_rate = 0.01;
};

// One scalar statistic of the sequential test.
struct TermStatistic {
  FaultTerm term = FaultTerm::kEncoderOffset;
  int cable = -1;       // -1 for load and load_cell_bias
  int component = 0;    // anchor: world axis 0-2; load: 0 mass, 1-3 CoM
  double z = 0.0;       // this rest's normalised score s / sqrt(I) (N(0,1) when nothing changed)
  // This rest's standardised shift delta: a change of the designed size
  // moves z by this much (the CUSUM gains delta^2 / 2 a rest on average).
  double standardised_shift = 0.0;
  double cusum_up = 0.0, cusum_down = 0.0;
  int onset_rest = -1;  // where the larger side last left zero (-1 while both are 0)
};

struct RestCheck {
  int rest = 0;        // index in the order add_rest saw them
  int sample_id = 0;
  std::optional<LocalizedPose> pose;  // the pose from the cables
  std::string why;                    // why no pose or no check, when either is missing
  bool checked = false;               // the check fit ran (else this rest fed no statistic)
  bool has_measured_pose = false;
  // Measured - from the cables, per world-frame component, in sigmas of the
  // pose from the cables (zeros without either).
  Eigen::Matrix<double, 6, 1> pose_difference_sigma = Eigen::Matrix<double, 6, 1>::Zero();
  // Standardised residuals of the check fit: r_i / sqrt(1 - h_ii).
  std::array<double, kCableCount> encoder_residual_sigma{};
  double force_residual_sigma = 0.0;
  std::vector<TermStatistic> statistics;
  double threshold = 0.0;  // h
  bool fired = false;      // this rest made the watch stale
};

// One candidate term fitted to the rests since the onset.
struct TermEstimate {
  FaultTerm term = FaultTerm::kEncoderOffset;
  int cable = -1;
  Eigen::VectorXd value;  // offset [m]; anchor shift [m] x y z; elongation [m]; load: mass [kg], CoM [m] x y z; bias [N]
  Eigen::VectorXd sigma;
  double chi_square_drop = 0.0;
  double aic_gain() const { return chi_square_drop - 2.0 * static_cast<double>(value.size()); }
};

// An anchor move against an offset slip of the same cable, over the rests
// since the onset (the calibration's own error marginalised as for every
// candidate). The two differ only through how the cable's direction varies
// over the rests: a move along the cable is an offset change to every rest.
struct AnchorOrOffset {
  int cable = -1;
  // 2 ln LR of anchor[i] over offset[i]: the difference of their chi-square
  // drops. Under an offset slip it is at most the chi-square (3 degrees of
  // freedom) of adding the anchor's move to the offset change.
  double log_likelihood_ratio = 0.0;
  double margin = 0.0;  // the anchor is named when 2 ln LR exceeds this (HealthWatchOptions::anchor_misnaming_rate)
  // How well the rests span the cable's directions: the sigma of an anchor
  // move in the direction these rests resolve best once an offset change
  // may explain it too (infinite when none) [m]. A move smaller than about
  // sqrt(margin) of these sigmas cannot win by the margin.
  double best_sigma_m = 0.0;
  // The fitted move's size in those sigmas: sqrt(d^T F d), F the anchor's
  // information beyond the offset's; 2 ln LR is about its square.
  double fitted_move_sigmas = 0.0;
  bool anchor_named() const { return log_likelihood_ratio > margin; }
  // The rests could tell a move of the fitted size from an offset: its
  // expected 2 ln LR reaches the margin.
  bool separable() const { return fitted_move_sigmas * fitted_move_sigmas >= margin; }
};

struct StaleFinding {
  int since_rest = 0;       // the change's onset (first rest of the fit)
  int since_sample_id = 0;
  int fired_at_rest = 0;
  int fired_at_sample_id = 0;
  int rests_fitted = 0;     // since the onset, up to the latest rest
  TermStatistic statistic;  // the one that crossed
  TermEstimate term;        // the best by Akaike's criterion
  std::vector<TermEstimate> alike;       // others within 4 of it
  std::vector<TermEstimate> candidates;  // all, best first
  // When the best candidate is an anchor or offset of a cable: which of the two.
  std::optional<AnchorOrOffset> anchor_or_offset;
  bool calibration_fault() const { return term.term != FaultTerm::kLoad; }
};

// What one checked rest tells about every term: the score b = -G~^T r and
// the information A = G~^T G~ over the term columns (offsets 0-3, anchors
// 4-15 as 4 + 3 i + axis, elongations 16-19, load 20-23, load-cell bias 24),
// so that a term's change theta over rests K is estimated as
// (sum_K A)^-1 sum_K b with chi-square drop b^T A^-1 b.
inline constexpr int kFaultColumns = 25;
struct RestInformation {
  int rest = 0;
  Eigen::Matrix<double, kFaultColumns, 1> score = Eigen::Matrix<double, kFaultColumns, 1>::Zero();
  Eigen::Matrix<double, kFaultColumns, kFaultColumns> information =
      Eigen::Matrix<double, kFaultColumns, kFaultColumns>::Zero();
};

class HealthWatch {
 public:
  // `calibration` is the committed one; a robot or calibration the check
  // cannot use makes every rest's check say why (RestCheck::why).
  HealthWatch(Robot robot, Calibration calibration, HealthWatchOptions options = {});
  HealthWatch(const HealthWatch&) = delete;
  HealthWatch& operator=(const HealthWatch&) = delete;

  RestCheck add_rest(const Sample& rest);
  bool stale() const { return finding_.has_value(); }
  const std::optional<StaleFinding>& finding() const { return finding_; }
  // The rests seen (in order) and the threshold h of the test.
  const std::vector<Sample>& rests() const { return rests_; }
  double threshold() const { return threshold_; }
  // The rests since the finding's onset (empty while not stale): what a re-fit uses.
  std::vector<Sample> rests_since_onset() const;

 private:
  void update_statistics(const RestInformation& info, RestCheck& out);
  void attribute();
  std::optional<AnchorOrOffset> anchor_or_offset(const RestInformation& before, const RestInformation& since) const;

  Robot robot_;
  Robot heavier_;  // the robot with a heavier platform: the load column by finite difference
  Calibration calibration_;
  HealthWatchOptions options_;
  std::string unusable_;  // why the calibration cannot be checked against, or empty
  std::vector<Sample> rests_;
  std::vector<RestInformation> information_;
  std::vector<TermStatistic> statistics_;
  std::vector<double> shifts_;  // theta_j per statistic
  Eigen::Matrix<double, 16, 16> baseline_information_;  // the calibration's error: inverse covariance, column order
  // kTracked: the information and score of the calibration's error so far
  // (baseline_information_ plus the rests'), and how many rests fed them.
  Eigen::Matrix<double, 16, 16> tracked_information_;
  Eigen::Matrix<double, 16, 1> tracked_score_ = Eigen::Matrix<double, 16, 1>::Zero();
  int tracked_rests_ = 0;
  double anchor_margin_ = 0.0;  // 2 ln LR above which an anchor is named over the offset
  std::array<int, kFaultColumns> onset_up_{}, onset_down_{};  // where each side last left zero
  double threshold_ = 0.0;
  double reference_payout_m_ = 0.0;
  std::optional<Pose> last_pose_;
  std::optional<StaleFinding> finding_;
};

}  // namespace cdpr
