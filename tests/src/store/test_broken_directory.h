#pragma once
// A store directory made unusable in a way that holds for root too (tests
// may run as root, where a read-only mode does not stop writes): the
// directory is moved aside and a plain file takes its name, so every write
// below it fails with ENOTDIR. restore() puts the directory back.

#include <filesystem>
#include <fstream>
#include <string>

namespace cdpr::store::test {

class BrokenDirectory {
 public:
  explicit BrokenDirectory(std::string dir) : dir_(std::move(dir)), aside_(dir_ + ".aside") {
    std::filesystem::rename(dir_, aside_);
    std::ofstream(dir_) << "not a directory\n";
  }
  ~BrokenDirectory() { restore(); }
  void restore() {
    if (restored_) return;
    restored_ = true;
    std::filesystem::remove(dir_);
    std::filesystem::rename(aside_, dir_);
  }

 private:
  std::string dir_, aside_;
  bool restored_ = false;
};

}  // namespace cdpr::store::test
