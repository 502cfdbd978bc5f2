// cdpr-calib: offline calibration tools for cable-driven parallel robots.
#include <CLI/CLI.hpp>

#include "diagnose_command.h"
#include "localize_command.h"
#include "solve_command.h"
#include "watch_command.h"
#include "version/version.h"

int main(int argc, char** argv) {
  CLI::App app{"cdpr-calib: offline self-calibration of cable-driven parallel robots with sagging cables"};
  app.set_version_flag("--version", cdpr::version::version_text("cdpr-calib"));
  app.require_subcommand(1);
  cdpr::tools::SolveArgs solve_args;
  cdpr::tools::add_solve_command(app, solve_args);
  cdpr::tools::DiagnoseArgs diagnose_args;
  cdpr::tools::add_diagnose_command(app, diagnose_args);
  cdpr::tools::LocalizeArgs localize_args;
  cdpr::tools::add_localize_command(app, localize_args);
  cdpr::tools::WatchArgs watch_args;
  cdpr::tools::add_watch_command(app, watch_args);
  CLI11_PARSE(app, argc, argv);
  if (app.got_subcommand("solve")) return cdpr::tools::run_solve(solve_args);
  if (app.got_subcommand("diagnose")) return cdpr::tools::run_diagnose(diagnose_args);
  if (app.got_subcommand("localize")) return cdpr::tools::run_localize(localize_args);
  if (app.got_subcommand("watch")) return cdpr::tools::run_watch(watch_args);
  return 1;
}
