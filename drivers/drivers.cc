// Anchors the drivers library target when no driver is compiled in yet.
namespace cdpr::drivers {
const char* const kDriversVersion = "1";
}  // namespace cdpr::drivers
