#include "solver/operation/calibration_variables.h"

#include <cmath>
#include <memory>

#include "solver/operation/joint_prior_factor.h"
#include "solver/operation/value_prior_factor.h"

namespace cdpr {
namespace {

bool fail(std::string* why, const std::string& what) {
  if (why) *why = what;
  return false;
}

// One value list of [effects] by name, of `size` values; empty when absent or of another length.
std::optional<std::vector<double>> values_named(const EffectValues& values, const std::string& name, std::size_t size) {
  const auto it = values.find(name);
  if (it == values.end() || it->second.size() != size) return std::nullopt;
  return it->second;
}

// The variable `key` at `value`: constant, or free under a prior of `sigma`
// (constant when any sigma is zero: the file knows no uncertainty for it).
void add_value(Problem& problem, Key key, const std::vector<double>& value, const std::vector<double>& sigma,
               CalibrationUncertainty uncertainty) {
  problem.add_vector(key, Eigen::Map<const Eigen::VectorXd>(value.data(), static_cast<Eigen::Index>(value.size())));
  bool known_sigma = uncertainty == CalibrationUncertainty::kPriors && sigma.size() == value.size();
  for (double s : sigma) known_sigma = known_sigma && s > 0.0 && std::isfinite(s);
  if (!known_sigma) {
    problem.set_constant(key);
    return;
  }
  problem.add_factor(std::make_unique<ValuePriorFactor>(key, value, sigma));
}

}  // namespace

std::optional<std::vector<Effect>> calibration_effects(const Calibration& calibration, std::string* why) {
  if (static_cast<int>(calibration.winches.size()) != kCableCount) {
    fail(why, "the calibration has " + std::to_string(calibration.winches.size()) + " winches, not " +
                  std::to_string(kCableCount));
    return std::nullopt;
  }
  std::vector<Effect> effects;
  for (const std::string& name : calibration.model) {
    if (name == "catenary") continue;
    if (name == "rigid") {
      fail(why, "a rigid-cable calibration: the pose from the cables needs the catenary model");
      return std::nullopt;
    }
    const std::optional<Effect> e = effect_from_model_name(name);
    if (!e) {
      fail(why, "unknown model term '" + name + "' in the calibration");
      return std::nullopt;
    }
    effects.push_back(*e);
  }
  return effects;
}

std::optional<EffectParameter> effect_parameter(Effect e, const EffectValues& values, std::string* why) {
  const std::vector<std::string> names = effect_value_names(e);
  EffectParameter out;
  for (const std::string& name : names) {
    const std::size_t size = names.size() > 1 ? 1 : static_cast<std::size_t>(effect_dimension(e));
    const auto value = values_named(values, name, size);
    if (!value) {
      fail(why, "the calibration's [effects] has no " + std::to_string(size) + "-valued '" + name + "' for term " +
                    std::string(effect_model_name(e)));
      return std::nullopt;
    }
    const auto sigma = values_named(values, name + "_sigma", size);
    out.value.insert(out.value.end(), value->begin(), value->end());
    out.sigma.insert(out.sigma.end(), sigma ? sigma->begin() : value->begin(), sigma ? sigma->end() : value->end());
    if (!sigma) std::fill(out.sigma.end() - static_cast<long>(size), out.sigma.end(), 0.0);
  }
  if (e == Effect::kElasticity) {
    // [effects] holds EA [N]; the solver's parameter is kappa = 1e6 / EA (effects.h),
    // its sigma by first order: sigma_kappa = sigma_EA * kappa / EA.
    const double ea = out.value[0];
    if (!(ea > 0.0)) {
      fail(why, "the calibration's axial_stiffness is not positive");
      return std::nullopt;
    }
    const double kappa = 1.0 / (ea * kComplianceScale);
    out.sigma[0] = out.sigma[0] * kappa / ea;
    out.value[0] = kappa;
  }
  return out;
}

bool add_calibration_variables(Problem& problem, const Calibration& calibration, const std::vector<Effect>& effects,
                               CalibrationUncertainty uncertainty, std::string* why,
                               const Eigen::Matrix<double, 4 * kCableCount, 4 * kCableCount>* joint) {
  if (static_cast<int>(calibration.winches.size()) != kCableCount) {
    return fail(why, "the calibration has " + std::to_string(calibration.winches.size()) + " winches");
  }
  const bool joint_prior = joint && uncertainty == CalibrationUncertainty::kPriors;
  if (joint_prior) {
    std::vector<Key> keys;
    std::vector<int> sizes;
    Eigen::VectorXd value(4 * kCableCount);
    for (int i = 0; i < kCableCount; ++i) {
      problem.add_vector(AnchorKey(i), calibration.winches[i].anchor_world);
      keys.push_back(AnchorKey(i));
      sizes.push_back(3);
      value.segment<3>(3 * i) = calibration.winches[i].anchor_world;
    }
    for (int i = 0; i < kCableCount; ++i) {
      problem.add_vector(OffsetKey(i), Eigen::VectorXd::Constant(1, calibration.winches[i].offset_m));
      keys.push_back(OffsetKey(i));
      sizes.push_back(1);
      value(3 * kCableCount + i) = calibration.winches[i].offset_m;
    }
    problem.add_factor(std::make_unique<JointPriorFactor>(keys, sizes, value, *joint));
  }
  for (int i = 0; i < kCableCount && !joint_prior; ++i) {
    const WinchCalibration& w = calibration.winches[i];
    add_value(problem, AnchorKey(i), {w.anchor_world.x(), w.anchor_world.y(), w.anchor_world.z()},
              {w.anchor_sigma.x(), w.anchor_sigma.y(), w.anchor_sigma.z()}, uncertainty);
  }
  for (int i = 0; i < kCableCount && !joint_prior; ++i) {
    const WinchCalibration& w = calibration.winches[i];
    add_value(problem, OffsetKey(i), {w.offset_m}, {w.offset_sigma_m}, uncertainty);
  }
  for (Effect e : effects) {
    const std::optional<EffectParameter> p = effect_parameter(e, calibration.effects, why);
    if (!p) return false;
    add_value(problem, EffectKey(e), p->value, p->sigma, uncertainty);
  }
  return true;
}

}  // namespace cdpr
