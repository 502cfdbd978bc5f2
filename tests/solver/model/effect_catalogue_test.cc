// The catalogue of model terms (solver/model/effects.h): the lists derived
// from it, and the docs' term tables, which are generated from its rows
// (CDPR_UPDATE_DOCS=1 rewrites them; `make docs`).
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "solver/model/effects.h"

namespace cdpr {
namespace {

std::string text_of(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string code(std::string_view name) { return "`" + std::string(name) + "`"; }

// "`axial_stiffness` [N]", "`encoder_scale` (4)", "`force_bias` [N], `force_gain`".
std::string values_text(const EffectDescriptor& d) {
  std::string text;
  for (int v = 0; v < d.value_count; ++v) {
    const EffectValueSpec& value = d.values[v];
    text += (v ? ", " : "") + code(value.name);
    if (value.size > 1) text += " (" + std::to_string(value.size) + ")";
    if (!value.unit.empty()) text += " [" + std::string(value.unit) + "]";
  }
  return text;
}

// docs/diagnosis.md "The model terms".
std::string diagnosis_table() {
  std::string out = "| term | parameters | calibration.toml `[effects]` | plausible size |\n|---|---|---|---|\n";
  for (const EffectDescriptor& d : kEffectCatalogue) {
    out += "| " + code(d.name) + " | " + std::string(d.parameters) + " | " + values_text(d) + " | " +
           std::string(d.plausible) + " |\n";
  }
  return out;
}

// docs/DESIGN.md "Model terms (effects)": the base cable model, then the terms.
std::string design_table() {
  std::string out =
      "| effect (`--model` name) | parameters | what it changes |\n|---|---|---|\n"
      "| cable sag (`catenary`) | none (density known) | straight line -> catenary shape, length and height |\n";
  for (const EffectDescriptor& d : kEffectCatalogue) {
    out += "| " + code(d.name) + " | " + std::string(d.parameters) + " | " + std::string(d.changes) + " |\n";
  }
  return out;
}

// Compares (or, with CDPR_UPDATE_DOCS set, rewrites) the generated part of a page.
void expect_generated(const std::string& page_name, const std::string& expected) {
  const std::string path = std::string(CDPR_SOURCE_DIR) + "/docs/" + page_name;
  const std::string begin_mark = "<!-- BEGIN terms: generated from solver/model/effects.h -->\n";
  const std::string end_mark = "<!-- END terms -->\n";
  std::string page = text_of(path);
  const std::size_t begin = page.find(begin_mark), end = page.find(end_mark);
  ASSERT_NE(begin, std::string::npos) << path << " lacks " << begin_mark;
  ASSERT_NE(end, std::string::npos) << path << " lacks " << end_mark;
  const std::size_t listing = begin + begin_mark.size();
  if (std::getenv("CDPR_UPDATE_DOCS") != nullptr) {
    page.replace(listing, end - listing, expected);
    std::ofstream(path) << page;
    return;
  }
  EXPECT_EQ(page.substr(listing, end - listing), expected)
      << "run make docs (CDPR_UPDATE_DOCS=1 build/tests/solver_model_tests --gtest_filter='EffectCatalogue.TheDocs*')";
}

TEST(EffectCatalogue, TheDocsTermTablesListTheCatalogue) {
  // GIVEN the catalogue WHEN the pages' term tables are compared with it THEN they agree
  expect_generated("diagnosis.md", diagnosis_table());
  expect_generated("DESIGN.md", design_table());
}

TEST(EffectCatalogue, APoseReferencePointOffThePlatformIsOutsideItsDomain) {
  // GIVEN fitted pose reference offsets with their sigmas
  const std::vector<double> sigma{0.2, 0.2, 0.03};
  // WHEN one lies on a 1 m platform, or beyond 0.5 m only within 3 sigma THEN it is plausible
  EXPECT_EQ(effect_domain_violation(Effect::kPoseReferenceOffset, {0.3, -0.1, 0.4}, sigma), "");
  EXPECT_EQ(effect_domain_violation(Effect::kPoseReferenceOffset, {1.0, 0.0, 0.2}, sigma), "");
  // AND a component 1.05 +- 0.03 m off is not: the term is mimicking something else
  EXPECT_EQ(effect_domain_violation(Effect::kPoseReferenceOffset, {0.6, 0.4, 1.05}, sigma),
            "pose reference point beyond 0.5 m by more than 3 sigma");
}

TEST(EffectCatalogue, NamesAreUniqueAndEveryListFollowsTheRows) {
  // GIVEN the catalogue
  std::set<std::string_view> names;
  for (int i = 0; i < kEffectCount; ++i) {
    const EffectDescriptor& d = kEffectCatalogue[i];
    // THEN each term has a name of its own, found back from it, listed in kAllEffects at its row
    EXPECT_TRUE(names.insert(d.name).second) << d.name;
    EXPECT_EQ(effect_from_model_name(d.name), d.effect);
    EXPECT_EQ(kAllEffects[i], d.effect);
    EXPECT_EQ(effect_dimension(d.effect), d.dimension);
    EXPECT_FALSE(d.description.empty() || d.parameters.empty() || d.changes.empty() || d.plausible.empty()) << d.name;
    // AND its [effects] values have their unit, and fill exactly its parameters
    EffectValues values;
    add_effect_values(d.effect, std::vector<double>(d.dimension, 0.5), std::vector<double>(d.dimension, 0.1), values);
    EXPECT_EQ(values.size(), 2u * static_cast<std::size_t>(d.value_count)) << d.name;
    for (const std::string& name : effect_value_names(d.effect)) {
      EXPECT_TRUE(values.contains(name) && values.contains(name + "_sigma")) << name;
      EXPECT_TRUE(effect_value_unit(name).has_value()) << name;
    }
  }
  EXPECT_FALSE(effect_from_model_name("catenary").has_value());
  EXPECT_FALSE(effect_value_unit("wind_force").has_value());
}

}  // namespace
}  // namespace cdpr
