#pragma once
// Why a data file (docs/FORMATS.md) was refused: which file, which line, which
// key or column, and what was wrong with it.

#include <string>

namespace cdpr {

struct FormatError {
  std::string file;    // path or source name as given by the caller
  int line = 0;        // 1-based; 0 when the error concerns the whole file
  std::string field;   // key (robot.toml: "winch[2].anchor") or column ("enc1"); may be empty
  std::string reason;  // what is wrong, e.g. "unknown key", "not a finite number"

  // "robot.toml:12: winch[2].anchor: expected an array of 3 numbers"
  std::string message() const;
};

}  // namespace cdpr
