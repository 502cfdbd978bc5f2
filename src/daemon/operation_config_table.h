#pragma once
// The key table of [operation] (daemon_config.h OperationConfig); daemon_config.cc binds it.

#include "src/daemon/config_table.h"
#include "src/daemon/daemon_config.h"

namespace cdpr::daemon {

Table<OperationConfig> operation_table();

}  // namespace cdpr::daemon
