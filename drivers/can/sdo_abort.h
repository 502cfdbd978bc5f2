#pragma once
// CiA 301 SDO abort codes (the table of the SDO abort transfer service) and
// their meaning, for error messages that say why a device refused.

#include <cstdint>

namespace cdpr::drivers::can {

constexpr std::uint32_t kSdoAbortToggle = 0x05030000;
constexpr std::uint32_t kSdoAbortTimeout = 0x05040000;
constexpr std::uint32_t kSdoAbortCommand = 0x05040001;
constexpr std::uint32_t kSdoAbortNoObject = 0x06020000;
constexpr std::uint32_t kSdoAbortLength = 0x06070010;
constexpr std::uint32_t kSdoAbortNoSubindex = 0x06090011;
constexpr std::uint32_t kSdoAbortValueRange = 0x06090030;
constexpr std::uint32_t kSdoAbortReadOnly = 0x06010002;
constexpr std::uint32_t kSdoAbortDeviceState = 0x08000022;

// "object does not exist in the object dictionary"; "unknown abort code"
// for codes outside the table.
const char* sdo_abort_text(std::uint32_t code);

}  // namespace cdpr::drivers::can
