#pragma once
// The one-line verdict of the model check (solver/diagnosis/diagnosis.h) on
// a run's data, for the run's log (run.toml `diagnosis`) and `calibctl show`:
//
//   "model explains the data (held-out normalized rms 1.02)"
//   "elasticity explains the data: axial_stiffness = 1.52e+06 +- 3.1e+04"
//   "load_cell_bias: force_bias = 12.1 +- 0.8; structure remains (held-out normalized rms 1.9, p = 2e-05)"
//   "structure remains that no known effect explains (held-out normalized rms 2.4, p = 1e-09)"
//   "model check could not run: <why>"
//
// followed by what else it found: "; orientation noise 2.31x robot.toml"
// per noise finding, "; load_cell_bias or load_cell indistinguishable on
// these poses (...)" per mimic set that stands.
//
// Values in the [effects] names and units of docs/FORMATS.md. The verdict
// only informs: the committed calibration keeps the daemon's model.

#include <string>
#include <string_view>
#include <vector>

#include "solver/diagnosis/diagnosis.h"

namespace cdpr::calibration {

std::string model_check_verdict(const Diagnosis& diagnosis);

// The model term names a verdict of model_check_verdict() names (with their
// values), in its order: what `calibctl commit --with-term` would add.
// Empty when it names none (the model explains the data, structure remains
// unexplained, the check could not run).
std::vector<std::string> model_check_terms(std::string_view verdict);

}  // namespace cdpr::calibration
