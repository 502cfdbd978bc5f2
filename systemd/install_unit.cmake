# Run by cmake --install for each unit (systemd/CMakeLists.txt), with
# cdpr_unit_source set: writes the unit to <prefix>/lib/systemd/system with
# its /usr/sbin/ and /usr/share/doc/ paths moved to the install prefix.
get_filename_component(unit_name "${cdpr_unit_source}" NAME)
file(READ "${cdpr_unit_source}" text)
string(REPLACE "/usr/sbin/" "${CMAKE_INSTALL_PREFIX}/sbin/" text "${text}")
string(REPLACE "/usr/share/doc/" "${CMAKE_INSTALL_PREFIX}/share/doc/" text "${text}")
set(unit_path "$ENV{DESTDIR}${CMAKE_INSTALL_PREFIX}/lib/systemd/system/${unit_name}")
message(STATUS "Installing: ${unit_path}")
file(WRITE "${unit_path}" "${text}")
list(APPEND CMAKE_INSTALL_MANIFEST_FILES "${unit_path}")
