#pragma once
// The key tables of the devices' sections of cdpr-calibd.toml ([winches],
// [winches.drive], [winches.encoder], [[winches.winch]], [load_cell],
// [pose], [button]); daemon_config.cc binds them with the others into the
// configuration, in the order of the file.

#include "src/daemon/config_table.h"
#include "src/daemon/daemon_config.h"

namespace cdpr::daemon {

Table<WinchesConfig> winches_table();
Table<drivers::can::DriveDescription> drive_table();
Table<drivers::can::EncoderDescription> encoder_table();
Table<drivers::can::WinchMechanics> mechanics_table();
// One table per cable, in robot.toml's [[winch]] order.
Table<drivers::can::CanWinchConfig> winch_table();
Table<LoadCellConfig> load_cell_table();
Table<PoseConfig> pose_table();
Table<ButtonConfig> button_table();

}  // namespace cdpr::daemon
