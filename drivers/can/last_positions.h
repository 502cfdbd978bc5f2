#pragma once
// Each winch's last unwrapped encoder position, kept in a file in the
// daemon's state directory so that a restart unwraps the first CiA 406
// reading (UNSIGNED32, wrapping at 0x6002) nearest where the cable was,
// not nearest the middle of the payout range: a cable past half the
// measuring range from there then reads the same after a restart.
//
// Format (TOML subset): `version = 1` and `winch<i> = <counts>` lines.
// Written as temp file, fsync, rename, fsync of the directory. An absent
// or unreadable file gives no positions (the payout-range centre is used).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace cdpr::drivers::can {

// `winches` entries, nullopt where the file has none (or there is no file).
std::vector<std::optional<std::int64_t>> read_last_positions(const std::string& path, std::size_t winches);

// Writes the present entries; false with `error` ("<path>: why") when it cannot.
bool write_last_positions(const std::string& path, const std::vector<std::optional<std::int64_t>>& counts,
                          std::string& error);

}  // namespace cdpr::drivers::can
