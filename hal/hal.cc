// Anchors the hal library target; the interfaces themselves are header-only.
namespace cdpr::hal {
const char* const kHalVersion = "1";
}  // namespace cdpr::hal
