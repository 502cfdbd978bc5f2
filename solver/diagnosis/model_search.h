#pragma once
// The pieces the model-discrepancy workflow (solver/diagnosis/diagnosis.h) is made of: a
// model is the list of effects on top of the catenary; it is fitted to all
// samples or cross-validated (each fold predicted by a fit without it), and
// it grows one effect at a time, a wider effect taking the place of a
// narrower one it contains (load_cell replaces load_cell_bias).

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "solver/diagnosis/diagnosis_options.h"
#include "solver/diagnosis/held_out.h"

namespace cdpr {

// "catenary+elasticity+...", for progress lines.
std::string model_text(const std::vector<Effect>& model);

// The model with e added; e replaces a narrower effect it contains.
std::vector<Effect> with_effect(const std::vector<Effect>& model, Effect e);

// The effect of the model that e replaces when added, if any.
std::optional<Effect> replaced_by(const std::vector<Effect>& model, Effect e);

// Whether adding e would add anything: not when the model has e or an effect containing it.
bool can_add(const std::vector<Effect>& model, Effect e);

// The model fitted to all samples with options.fit (no progress).
CalibrationResult fit_all(const Robot& robot, const std::vector<Sample>& samples, const DiagnosisOptions& options,
                          const std::vector<Effect>& model);

// options.folds-fold cross-validation (sample k held out in fold k % folds),
// pooled over the folds; `ok` false with the first failure's reason.
HeldOutEvaluation cross_validate(const Robot& robot, const std::vector<Sample>& samples,
                                 const DiagnosisOptions& options, const std::vector<Effect>& model);

// Why the last `count` effects of a fit on all samples are unphysical (or the
// fit failed), empty when they are physical.
std::string domain_violation(const CalibrationResult& fit, std::size_t count);

// Progress: one line through options.progress, when set.
void report(const DiagnosisOptions& options, const std::string& line);
std::string fixed(double value, int digits);  // "%.*f"
std::string scientific(double value);         // "%.2g"

}  // namespace cdpr
