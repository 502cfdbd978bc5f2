#pragma once
// The [effects] table shared by calibration.toml and truth.toml (docs/FORMATS.md):
// fitted (or true) parameters of extra model terms, by name. Each value is a
// number (scalar terms, e.g. axial_stiffness) or an array of numbers
// (per-cable terms, e.g. encoder_scale). Names are open-ended: which effects
// exist is the solver's business, not the file format's.

#include <string>

#include <toml++/toml.h>

#include "solver/model/calibration.h"
#include "src/formats/toml_reader.h"

namespace cdpr::formats {

// Reads the optional [effects] table of `root`; empty when absent.
EffectValues read_effects(TomlReader& reader, const toml::table& root);

// Appends an [effects] table (nothing when `effects` is empty); one value is
// written as a number, several as an array.
void append_effects(std::string& out, const EffectValues& effects);

}  // namespace cdpr::formats
