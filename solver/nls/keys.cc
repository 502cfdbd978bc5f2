#include "solver/nls/keys.h"

namespace cdpr {

std::string to_string(const Key& key) {
  const char* name = "?";
  switch (key.kind) {
    case VariableKind::kPose: name = "pose"; break;
    case VariableKind::kReferenceForce: name = "reference_force"; break;
    case VariableKind::kAnchor: name = "anchor"; break;
    case VariableKind::kOffset: name = "offset"; break;
    case VariableKind::kEffect: name = "effect"; break;
  }
  return std::string(name) + "[" + std::to_string(key.index) + "]";
}

}  // namespace cdpr
