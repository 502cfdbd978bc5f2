// One default per key: where a library's options struct gives its member a
// default (PlannerOptions, the drive's description, the monitor's limits,
// ...), the key table's row gives the same, so that a tool or test using the
// struct as it is runs with the daemon's settings.

#include <set>
#include <string>

#include <gtest/gtest.h>

#include "src/daemon/daemon_config.h"

namespace cdpr::daemon {
namespace {

// Keys whose struct member has no default of its own (the daemon's own
// structs, the per-cable node ids and scales, the state directory): the
// table is their only default.
bool only_the_table_has_a_default(const std::string& key) {
  static const std::set<std::string> daemon_keys = {"robot", "unsafe_ok", "store.state_dir", "winches.endpoint",
                                                    "load_cell.endpoint", "load_cell.preset",
                                                    "load_cell.poll_interval_ms", "load_cell.fault_timeout_ms"};
  for (const std::string prefix : {"control.", "loop.", "history.", "pose.", "button.", "winches.winch["}) {
    if (key.starts_with(prefix)) return true;
  }
  return daemon_keys.count(key) > 0;
}

TEST(ConfigDefaults, TheTablesDefaultsAreTheOptionsStructsDefaults) {
  // GIVEN the libraries' options structs as they are, and the tables' defaults
  DaemonConfig structs{};
  structs.winches.winches.resize(4);
  const auto from_structs = daemon_config_values(structs);
  const auto from_tables = daemon_config_values(default_daemon_config());
  // WHEN every key a struct gives a default is compared
  std::string disagreements;
  for (const auto& [key, table_value] : from_tables) {
    if (only_the_table_has_a_default(key)) continue;
    const auto found = from_structs.find(key);
    ASSERT_NE(found, from_structs.end()) << key;
    if (found->second != table_value) disagreements += "\n  " + key + ": table " + table_value + ", struct " + found->second;
  }
  // THEN they are the same
  EXPECT_EQ(disagreements, "") << "defaults written twice that disagree:" << disagreements;
}

}  // namespace
}  // namespace cdpr::daemon
