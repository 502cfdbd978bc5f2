#include "src/formats/text_file.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>

namespace cdpr::formats {

Expected<std::string, FormatError> read_text_file(const std::string& path) {
  // stdio rather than iostreams: errno then says why an open or read failed.
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!file) return Unexpected{FormatError{path, 0, "", std::string("cannot open: ") + std::strerror(errno)}};
  std::string text;
  char buffer[8192];
  std::size_t count = 0;
  while ((count = std::fread(buffer, 1, sizeof buffer, file.get())) > 0) text.append(buffer, count);
  if (std::ferror(file.get())) {
    return Unexpected{FormatError{path, 0, "", std::string("cannot read: ") + std::strerror(errno)}};
  }
  return text;
}

}  // namespace cdpr::formats
