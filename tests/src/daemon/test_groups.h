// Groups the control-socket tests can give the socket to, or know nobody has.
#pragma once

#include <grp.h>
#include <unistd.h>

#include <optional>
#include <vector>

namespace cdpr::daemon {

// A group this process may give a file to other than its own: any group as
// root, else one of its supplementary groups.
inline std::optional<gid_t> another_group() {
  if (geteuid() == 0) {
    setgrent();
    std::optional<gid_t> found;
    while (const group* entry = getgrent()) {
      if (entry->gr_gid != getegid()) {
        found = entry->gr_gid;
        break;
      }
    }
    endgrent();
    return found;
  }
  std::vector<gid_t> groups(static_cast<std::size_t>(getgroups(0, nullptr)));
  groups.resize(static_cast<std::size_t>(getgroups(static_cast<int>(groups.size()), groups.data())));
  for (const gid_t g : groups) {
    if (g != getegid()) return g;
  }
  return std::nullopt;
}

// A group id that no group has.
inline gid_t unused_group_id() {
  gid_t id = 4242;
  while (getgrgid(id) != nullptr) ++id;
  return id;
}

}  // namespace cdpr::daemon
