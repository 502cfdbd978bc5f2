// The model check's one-line verdict: an effect named with value +- sigma,
// "structure remains", or "model explains the data".

#include "src/calibration/model_check_verdict.h"

#include <gtest/gtest.h>

namespace cdpr::calibration {
namespace {

Diagnosis finished(std::vector<Effect> model, bool structure_remains) {
  Diagnosis d;
  d.ok = true;
  d.steps.emplace_back();
  d.steps.back().model = std::move(model);
  d.structure_remains = structure_remains;
  d.structure_p_value = structure_remains ? 2e-5 : 0.4;
  return d;
}

TEST(ModelCheckVerdict, NamesTheEffectWithItsValueAndSigma) {
  // GIVEN a check that added elasticity and left nothing above the noise
  Diagnosis d = finished({Effect::kElasticity}, false);
  d.final_fit.calibration.effects["axial_stiffness"] = {1.52e6};
  d.final_fit.calibration.effects["axial_stiffness_sigma"] = {3.1e4};
  // WHEN put in words THEN the effect, its value and sigma come first
  const std::string verdict = model_check_verdict(d);
  EXPECT_EQ(verdict.rfind("elasticity: axial_stiffness = 1.52e+06 +- 3.1e+04 (explains the data", 0), 0u) << verdict;
}

TEST(ModelCheckVerdict, SaysWhenStructureRemainsOrTheModelExplainsTheData) {
  EXPECT_EQ(model_check_verdict(finished({}, true)).rfind("structure remains that no known effect explains", 0), 0u)
      << model_check_verdict(finished({}, true));
  EXPECT_EQ(model_check_verdict(finished({}, false)).rfind("model explains the data", 0), 0u)
      << model_check_verdict(finished({}, false));
  Diagnosis failed;
  failed.message = "too few samples";
  EXPECT_EQ(model_check_verdict(failed), "model check could not run: too few samples");
}

TEST(ModelCheckVerdict, SaysWhichNoiseIsLargerThanStatedAndWhichTermsLookAlike) {
  // GIVEN a check that took load_cell_bias, with load_cell about as good, and found the orientation noisier
  Diagnosis d = finished({Effect::kLoadCellBias}, false);
  d.final_fit.calibration.effects["force_bias"] = {20.5};
  d.noise.push_back({NoiseGroup::kOrientation, 2.31});
  MimicSet set;
  set.members.resize(2);
  set.members[0].effect = Effect::kLoadCellBias;
  set.members[1].effect = Effect::kLoadCell;
  d.mimic_sets.push_back(set);
  // WHEN put in words
  const std::string verdict = model_check_verdict(d);
  // THEN both findings follow the term, and only the term reads back as one
  EXPECT_NE(verdict.find("; orientation noise 2.31x robot.toml"), std::string::npos) << verdict;
  EXPECT_NE(verdict.find("; load_cell_bias or load_cell indistinguishable on these poses"), std::string::npos)
      << verdict;
  EXPECT_EQ(model_check_terms(verdict), std::vector<std::string>{"load_cell_bias"}) << verdict;
}

TEST(ModelCheckVerdict, TheTermsItNamesAreReadBackFromItsText) {
  // GIVEN verdicts naming two effects (structure remaining), one, and none
  Diagnosis two = finished({Effect::kLoadCellBias, Effect::kElasticity}, true);
  two.final_fit.calibration.effects["force_bias"] = {12.1};
  two.final_fit.calibration.effects["force_bias_sigma"] = {0.8};
  two.final_fit.calibration.effects["axial_stiffness"] = {1.5e6};
  Diagnosis failed;
  failed.message = "load_cell_bias: cannot fit";
  // WHEN their terms are read back THEN exactly the named effects come out, in order
  EXPECT_EQ(model_check_terms(model_check_verdict(two)), (std::vector<std::string>{"load_cell_bias", "elasticity"}));
  EXPECT_TRUE(model_check_terms(model_check_verdict(finished({}, true))).empty());
  EXPECT_TRUE(model_check_terms(model_check_verdict(finished({}, false))).empty());
  EXPECT_TRUE(model_check_terms(model_check_verdict(failed)).empty());
  EXPECT_TRUE(model_check_terms("").empty());
}

}  // namespace
}  // namespace cdpr::calibration
