#include "solver/diagnosis/pair_search.h"

#include <string>
#include <utility>

#include "solver/diagnosis/model_search.h"

namespace cdpr {

std::optional<PairChoice> best_pair(const Robot& robot, const std::vector<Sample>& samples,
                                    const DiagnosisOptions& options, const std::vector<Effect>& model,
                                    const std::vector<Effect>& candidates, const std::vector<std::size_t>& strong,
                                    const std::vector<CalibrationResult>& single_fits,
                                    const HeldOutEvaluation& best_single) {
  const auto same_term = [](Effect x, Effect y) { return x == y || effect_contains(x, y) || effect_contains(y, x); };
  const Effect leader = candidates[strong.front()];
  // Pairs of two different terms, neither a form of the best single.
  std::vector<std::pair<std::size_t, std::size_t>> eligible;
  for (std::size_t a = 1; a < strong.size(); ++a) {
    for (std::size_t b = a + 1; b < strong.size(); ++b) {
      const Effect first = candidates[strong[a]], second = candidates[strong[b]];
      if (!same_term(first, second) && !same_term(first, leader) && !same_term(second, leader)) {
        eligible.emplace_back(a, b);
      }
    }
  }
  if (eligible.empty()) return std::nullopt;
  const double level = options.alpha / static_cast<double>(eligible.size());
  std::optional<PairChoice> best;
  for (const auto& [a, b] : eligible) {
    const Effect first = candidates[strong[a]], second = candidates[strong[b]];
    const std::vector<Effect> with = with_effect(with_effect(model, first), second);
    HeldOutEvaluation f = cross_validate(robot, samples, options, with);
    if (!f.ok) continue;
    const HeldOutComparison c = compare_held_out(best_single, f);
    CalibrationResult fit = fit_all(robot, samples, options, with);
    const FitComparison over_first = compare_fits(single_fits[strong[a]], fit);
    const FitComparison over_second = compare_fits(single_fits[strong[b]], fit);
    const double aic_gain = akaike_gain(single_fits[strong.front()], fit);
    report(options, "  try pair " + std::string(effect_model_name(first)) + " + " +
                        std::string(effect_model_name(second)) + ": against the best single, held-out chi2 drop " +
                        fixed(c.drop, 1) + " (paired t " + fixed(c.t_statistic, 2) + "), Akaike gain on all samples " +
                        fixed(aic_gain, 1) + "; on all samples p " + scientific(over_first.p_value) + " over " +
                        std::string(effect_model_name(first)) + " alone, p " + scientific(over_second.p_value) +
                        " over " + std::string(effect_model_name(second)) +
                        " alone (needs a positive drop and gain, each p < " + scientific(level) + ")");
    if (c.drop <= 0.0 || aic_gain <= 0.0 || 2 * c.paired_poses < static_cast<int>(best_single.poses.size())) {
      continue;
    }
    if (!over_first.comparable || !over_second.comparable || over_first.p_value >= level ||
        over_second.p_value >= level) {
      continue;
    }
    if (best && c.drop <= best->against_best.drop) continue;
    if (const std::string why = domain_violation(fit, 2); !why.empty()) {
      report(options, "  reject pair: " + why);
      continue;
    }
    best = PairChoice{strong[a], strong[b], std::move(f), std::move(fit), c, over_first, level};
  }
  return best;
}

}  // namespace cdpr
