#pragma once
// The sentence under a text list of gross errors that holds a suspect group
// (SensorReading::group): cdpr-calib's summary and calibctl show print the
// same words. Header-only, so the control-socket client needs no report code.

namespace cdpr::report {

inline constexpr const char* kSuspectGroupNote =
    "(a suspect group: its row holds a gross error the data cannot pin on one of its readings; all of them were "
    "left out)";

}  // namespace cdpr::report
