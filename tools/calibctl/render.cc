#include "calibctl/render.h"

#include <algorithm>
#include <cstdio>

#include "src/report/suspect_group_note.h"

namespace cdpr::calibctl {
namespace {

template <class... Args>
std::string format(const char* pattern, Args... args) {
  char buffer[512];
  std::snprintf(buffer, sizeof(buffer), pattern, args...);
  return buffer;
}

// Status lines longer than this are wrapped (at spaces; a longer word, such
// as a path, stays whole), so that each label starts a line of its own.
constexpr std::size_t kLineWidth = 100;

// "  label: text", wrapped with the continuation indented.
void append_wrapped(std::string& out, const std::string& label, const std::string& text) {
  std::string line = "  " + label + ":";
  const std::string indent = "    ";
  std::size_t at = 0;
  while (at < text.size()) {
    std::size_t end = text.find(' ', at);
    if (end == std::string::npos) end = text.size();
    const std::string word = text.substr(at, end - at);
    if (line.size() + 1 + word.size() > kLineWidth && line.size() > indent.size() + 3 + label.size()) {
      out += line + "\n";
      line = indent + word;
    } else if (!word.empty() || line.size() > indent.size()) {
      line += " " + word;
    }
    at = end + 1;
  }
  out += line + "\n";
}

void append_if(std::string& out, const char* label, const JsonValue& text) {
  if (!text.string().empty()) append_wrapped(out, label, text.string());
}

double at(const JsonValue& vector, std::size_t k) {
  const auto elements = vector.array();
  return k < elements.size() ? elements[k].number() : 0.0;
}

// The command that commits a run refitted with the terms its model check
// named, when it named any: the operator's explicit choice.
void append_refit_hint(std::string& out, const JsonValue& run) {
  std::string terms;
  for (const JsonValue& term : run["named_terms"].array()) terms += (terms.empty() ? "" : ",") + term.string();
  if (terms.empty()) return;
  const std::string entry = run["entry"].string();
  const std::string name = entry.substr(entry.find_last_of('/') + 1);
  out += "  to commit a calibration with " + terms + ": calibctl commit --with-term " + terms +
         (name.empty() ? "" : " " + name) + "\n";
}

// "elapsed 412.3 s (daemon clock), about 180 s left; largest sigma: anchor 0.031 m (target 0.02), offset ..."
std::string waypoint_progress(const JsonValue& s) {
  if (s["strategy"].string().empty()) return "";
  std::string out = "  " + s["strategy"].string();
  // elapsed_s is the daemon's monotonic clock, not the robot's (a virtual robot's runs faster).
  if (!s["elapsed_s"].is_null()) out += format(": elapsed %.1f s (daemon clock)", s["elapsed_s"].number());
  if (!s["time_left_s"].is_null()) out += format(", about %.0f s left", s["time_left_s"].number());
  if (!s["stop_reason"].string().empty()) out += " (waypoints ended: " + s["stop_reason"].string() + ")";
  if (const JsonValue sigma = s["sigma"]; !sigma.is_null()) {
    out += format("; largest sigma: anchor %.4f m (target %.4g), offset %.4f m (target %.4g)",
                  sigma["anchor"].number(), sigma["target_anchor"].number(), sigma["offset"].number(),
                  sigma["target_offset"].number());
  }
  return out + "\n";
}

// "  winch 0 drive 1: operational, quick stop active, 0x603F ..., last EMCY ..., PDO 12 ms ago"
void append_nodes(std::string& out, const JsonValue& nodes) {
  if (nodes.array().empty()) return;
  out += "  nodes:\n";
  for (const JsonValue& n : nodes.array()) {
    out += format("    winch %d %s %d: %s", n["winch"].integer(), n["role"].string().c_str(), n["node_id"].integer(),
                  n["nmt"].string().c_str());
    if (!n["configured"].boolean()) out += " (not configured)";
    if (!n["cia402"].string().empty()) out += ", " + n["cia402"].string();
    if (!n["error_code"].string().empty()) out += ", 0x603F " + n["error_code"].string();
    if (!n["last_emcy"].string().empty()) out += ", last EMCY " + n["last_emcy"].string();
    const JsonValue pdo_age_ms = n["pdo_age_ms"];
    out += pdo_age_ms.is_null() ? std::string(", no PDO yet") : format(", PDO %.0f ms ago", pdo_age_ms.number());
    out += "\n";
  }
}

}  // namespace

std::string render_refit(const JsonValue& refit) {
  if (refit.is_null()) return "no refit was requested\n";
  std::string out = format("refit of %s with %s: %s: %s\n", refit["run"].string().c_str(),
                           refit["terms"].string().c_str(), refit["state"].string().c_str(),
                           refit["message"].string().c_str());
  if (!refit["entry"].string().empty()) out += "  kept in " + refit["entry"].string() + " (with its report.html)\n";
  return out;
}

// Watch mode's part of the status (docs/operation.md).
void append_operation(std::string& out, const JsonValue& o) {
  if (o.is_null()) return;
  out += format("watch: %s (calibration %d), %d rests, %d localized from the cables; %s\n", o["state"].string().c_str(),
                o["calibration_seq"].integer(), o["rests"].integer(), o["localized"].integer(),
                o["detail"].string().c_str());
  if (const JsonValue last = o["last_rest"]; !last.is_null()) {
    const JsonValue& p = last["position"];
    const JsonValue& sp = last["position_sigma"];
    out += format("  last rest %d, %.0f s ago: at %.3f, %.3f, %.3f m, sigma %.1f, %.1f, %.1f mm; onboard pose %.1f "
                  "sigma away\n", last["rest"].integer(), last["age_s"].number(), at(p, 0), at(p, 1), at(p, 2),
                  1e3 * at(sp, 0), 1e3 * at(sp, 1), 1e3 * at(sp, 2), last["onboard_sigmas"].number());
  }
  append_if(out, "last problem", o["last_problem"]);
  if (const JsonValue f = o["finding"]; !f.is_null()) {
    const auto value = f["value"].array(), sigma = f["sigma"].array();
    std::string size;
    for (std::size_t k = 0; k < value.size(); ++k) {
      size += format("%s%.4g +- %.2g", k == 0 ? "" : ", ", value[k].number(), k < sigma.size() ? sigma[k].number() : 0.0);
    }
    append_wrapped(out, "CALIBRATION STALE",
                   f["meaning"].string() + " (" + f["term"].string() + ": " + size + "), since rest " +
                       std::to_string(f["since_rest"].integer()) + ", flagged at rest " +
                       std::to_string(f["fired_at_rest"].integer()) + " " + format("%.0f", f["fired_s_ago"].number()) +
                       " s ago" + (f["calibration_fault"].boolean() ? "" : "; not a calibration fault"));
  }
  append_if(out, "re-fit", o["refit"]);
}

std::string render_status(const JsonValue& s) {
  std::string out = format("%s", s["state"].string().c_str());
  if (s["waypoints"].integer() > 0) {
    out += format("  waypoint %d/%d  samples %d  skipped %d", s["waypoint"].integer(), s["waypoints"].integer(),
                  s["samples"].integer(), s["skipped"].integer());
  }
  out += format("  %.0f%%", 100.0 * s["progress"].number());
  if (!s["elapsed_s"].is_null()) out += format("  %.1f s", s["elapsed_s"].number());
  out += "\n";
  out += waypoint_progress(s);
  append_if(out, "detail", s["detail"]);
  append_if(out, "note", s["note"]);
  append_if(out, "faults", s["device_faults"]);
  append_if(out, "reason", s["reason"]);
  if (s["committed_seq"].integer() > 0) out += format("  committed: calibration %d\n", s["committed_seq"].integer());
  append_if(out, "interrupted", s["interrupted"]);
  for (const JsonValue& problem : s["store_problems"].array()) append_if(out, "store", problem);
  if (s["pending_commit"].boolean()) {
    out += "  pending: a fit whose commit failed is kept; `calibctl commit` commits it once the cause is fixed\n";
  }
  if (const JsonValue run = s["run"]; !run.is_null()) {
    const std::string entry = run["entry"].string();
    out += "  run: " + run["outcome"].string() + format(", %d samples, data in ", run["samples"].integer()) +
           (entry.empty() ? "(not kept)" : entry) + "\n";
    append_if(out, "model check", run["diagnosis"]);
    // Once the refit of this run is committed, the hint is done with.
    const JsonValue refit = s["refit"];
    const bool refit_committed =
        !refit.is_null() && refit["state"].string() == "committed" && entry.ends_with("/" + refit["run"].string());
    if (!refit_committed) append_refit_hint(out, run);
  }
  if (const JsonValue refit = s["refit"]; !refit.is_null()) out += "  " + render_refit(refit);
  append_operation(out, s["operation"]);
  append_nodes(out, s["nodes"]);
  return out;
}

std::string render_progress(const JsonValue& s) {
  std::string out = format("[%3.0f%%] %-9s", 100.0 * s["progress"].number(), s["state"].string().c_str());
  if (s["waypoints"].integer() > 0) {
    out += format(" %2d/%d (%d sampled, %d skipped)", s["waypoint"].integer(), s["waypoints"].integer(),
                  s["samples"].integer(), s["skipped"].integer());
  }
  if (!s["detail"].string().empty()) out += "  " + s["detail"].string();
  return out;
}

std::string render_show(const JsonValue& s) {
  if (!s["present"].boolean()) return "no calibration committed yet\n";
  std::string out = format("calibration %d  created %s  robot %s  %d samples  model", s["seq"].integer(),
                           s["created"].string().c_str(), s["robot"].string().c_str(), s["samples"].integer());
  for (const JsonValue& term : s["model"].array()) out += " " + term.string();
  out += "\n";
  out += "cable  anchor x, y, z [m]                    sigma x, y, z [m]         offset [m]  sigma [m]\n";
  int cable = 0;
  for (const JsonValue& w : s["winches"].array()) {
    const JsonValue& a = w["anchor"];
    const JsonValue& sa = w["anchor_sigma"];
    out += format("%5d  %11.4f %11.4f %11.4f    %7.4f %7.4f %7.4f    %10.4f  %9.4f\n", cable++, at(a, 0), at(a, 1),
                  at(a, 2), at(sa, 0), at(sa, 1), at(sa, 2), w["offset"].number(), w["offset_sigma"].number());
  }
  const JsonValue& fit = s["fit"];
  out += format("fit: cost %.4g -> %.4g in %d iterations, rms encoder %.4f m, rms force %.3f N\n",
                fit["cost_initial"].number(), fit["cost_final"].number(), fit["iterations"].integer(),
                fit["rms_encoder"].number(), fit["rms_force"].number());
  const std::string warning = s["model_warning"].string();
  if (!warning.empty()) out += "MODEL WARNING: " + warning + "\n";
  const auto rejected = s["rejected"].array();
  if (!rejected.empty()) {
    out += "gross errors (normalised residual at the robust fit; left out of the final fit):\n";
    for (const JsonValue& r : rejected) {
      const std::string sensor = r["sensor"].string();
      out += format("  row %4d  %-7s", r["row"].integer(), sensor.c_str());
      out += sensor == "force" ? std::string(8, ' ') : format(" cable %d", r["cable"].integer());
      out += format("  %+8.1f sigma", r["residual"].number());
      if (const JsonValue& members = r["group_members"]; !members.is_null()) {
        out += "  suspect group: " + members.string();
      } else if (const JsonValue& group = r["group"]; !group.is_null() && group.integer() != 0) {
        out += format("  suspect group %d", group.integer());  // a daemon that does not name the members
      }
      out += "\n";
    }
    if (std::any_of(rejected.begin(), rejected.end(), [](const JsonValue& r) { return !r["group"].is_null(); })) {
      out += std::string("  ") + report::kSuspectGroupNote + "\n";
    }
  }
  if (const JsonValue run = s["run"]; !run.is_null()) {
    out += format("run: %s, %d samples, %d skipped, run time %.1f s (daemon clock), data in %s\n", run["outcome"].string().c_str(),
                  run["samples"].integer(), run["skipped"].integer(), run["robot_time_s"].number(),
                  run["entry"].string().c_str());
    if (!run["diagnosis"].string().empty()) out += "model check: " + run["diagnosis"].string() + "\n";
    append_refit_hint(out, run);
    if (!run["report"].is_null()) out += "report: " + run["report"].string() + "\n";
  }
  return out;
}

std::string render_history(const JsonValue& s) {
  const auto& entries = s["history"].array();
  if (entries.empty()) return "no stored calibrations\n";
  std::string out;
  for (const JsonValue& e : entries) {
    out += format("%c %6d  ", e["current"].boolean() ? '*' : ' ', e["seq"].integer());
    if (e["valid"].boolean()) {
      out += format("%s  robot %s  %d samples\n", e["created"].string().c_str(), e["robot"].string().c_str(),
                    e["samples"].integer());
    } else {
      out += "unreadable: " + e["problem"].string() + "\n";
    }
  }
  return out;
}

}  // namespace cdpr::calibctl
