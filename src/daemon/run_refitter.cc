#include "src/daemon/run_refitter.h"

#include <chrono>
#include <utility>

#include "solver/model/effects.h"
#include "src/report/sections.h"
#include "src/store/kept_run.h"

namespace cdpr::daemon {
namespace {

std::string known_terms() {
  std::string text;
  for (const Effect effect : kAllEffects) text += (text.empty() ? "" : ", ") + std::string(effect_model_name(effect));
  return text;
}

// The effects of "load_cell_bias" or "elasticity,load_cell_bias"; the error
// names the first unknown term, or why the terms cannot be fitted together.
Expected<std::vector<Effect>, std::string> parse_terms(const std::string& terms) {
  std::vector<Effect> effects;
  std::size_t begin = 0;
  while (begin <= terms.size()) {
    const std::size_t end = std::min(terms.find(',', begin), terms.size());
    const std::string name = terms.substr(begin, end - begin);
    const auto effect = effect_from_model_name(name);
    if (!effect) return Unexpected{"unknown model term '" + name + "' (known: " + known_terms() + ")"};
    effects.push_back(*effect);
    begin = end + 1;
  }
  if (const std::string conflict = effect_set_conflict(effects); !conflict.empty()) {
    return Unexpected{"the terms " + terms + " cannot be fitted together: " + conflict};
  }
  return effects;
}

std::vector<std::string> value_names(const EffectValues& effects) {
  std::vector<std::string> names;
  for (const auto& [name, values] : effects) {
    if (!name.ends_with("_sigma")) names.push_back(name);
  }
  return names;
}

}  // namespace

RunRefitter::RunRefitter(Robot robot, std::string history_dir, store::CalibrationStore& store,
                         CalibrationOptions fit, calibration::ValidationLimits limits,
                         std::function<std::string()> utc_now_text, std::function<void(const std::string&)> log)
    : robot_(std::move(robot)),
      history_(std::move(history_dir)),
      store_(store),
      fit_options_(std::move(fit)),
      limits_(limits),
      utc_now_text_(std::move(utc_now_text)),
      log_(std::move(log)) {
  fit_options_.progress = nullptr;  // the worker reports nothing while it fits
}

RunRefitter::~RunRefitter() {
  if (fitting_) fit_.wait();
}

Expected<std::string, std::string> RunRefitter::start_refit(int run, const std::string& terms) {
  if (fitting_) return Unexpected{"a refit of " + status_->run + " is already running"};
  const auto effects = parse_terms(terms);
  if (!effects) return Unexpected{effects.error()};
  auto kept = store::read_kept_run(history_, run, robot_.name, "refitted");
  if (!kept) return Unexpected{kept.error()};
  const std::string name = store::RunHistory::entry_name(kept->entry.run);
  job_ = CommittedRefit{kept->entry.log, std::move(kept->robot), std::move(kept->samples), fit_options_, {}, 0, terms};
  job_.source_log.run = kept->entry.run;
  job_.options.cable_model = CableModelKind::kCatenary;
  job_.options.effects = *effects;
  committed_.reset();
  std::vector<std::string> model{"catenary"};
  for (const Effect effect : *effects) model.emplace_back(effect_model_name(effect));
  const std::string what =
      name + " (" + std::to_string(job_.samples.size()) + " samples) with " + report::model_text(model);
  // Copies: the worker shares nothing with the loop thread.
  fit_ = std::async(std::launch::async, [robot = job_.robot, samples = job_.samples, options = job_.options] {
    return calibrate(robot, samples, options);
  });
  fitting_ = true;
  status_ = control::RefitStatus{name, terms, "running", "fitting " + what, 0, ""};
  if (log_) log_("refit: " + status_->message + " (the operator's request)");
  return "refitting " + what + "; `calibctl status` shows the outcome";
}

void RunRefitter::finish(const char* state, std::string message) {
  status_->state = state;
  status_->message = std::move(message);
  if (log_) log_("refit of " + status_->run + " " + state + ": " + status_->message);
}

bool RunRefitter::poll(bool calibration_running) {
  if (!fitting_ || fit_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return false;
  fitting_ = false;
  CalibrationResult result = fit_.get();
  const std::string& run = status_->run;
  if (calibration_running) {
    finish("refused", "not committed: a calibration started while " + run + " was refitted (ask again after it)");
    return true;
  }
  if (!result.ok) {
    finish("failed", "the fit of " + run + " failed: " + result.message);
    return true;
  }
  const auto current = store_.load_current();
  if (!current) {
    finish("failed", "not committed: the current calibration is unreadable: " + current.error().message());
    return true;
  }
  const Calibration* previous = *current ? &(*current)->calibration : nullptr;
  const calibration::ValidationResult validation = calibration::validate_fit(result, job_.robot, previous, limits_);
  if (!validation.accepted()) {
    finish("refused", "fit refused: " + validation.summary());
    return true;
  }
  Calibration& calibration = result.calibration;
  calibration::stamp_for_commit(calibration, job_.robot, job_.samples.size(), utc_now_text_);
  const auto committed = store_.commit(calibration);
  if (!committed) {
    finish("failed", "not committed: store: " + committed.error().message());
    return true;
  }
  status_->committed_seq = *committed;
  finish("committed", "committed calibration " + std::to_string(*committed) + ": " + run + " refitted with " +
                          report::model_text(calibration.model) + " (" +
                          report::effect_values_text(calibration.effects, value_names(calibration.effects)) + ")");
  job_.fit = std::move(result);
  job_.seq = *committed;
  committed_ = std::move(job_);
  return true;
}

std::optional<CommittedRefit> RunRefitter::take_committed() { return std::exchange(committed_, std::nullopt); }

}  // namespace cdpr::daemon
