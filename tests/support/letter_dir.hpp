#pragma once
/// @file letter_dir.hpp
/// A fresh temporary folder whose name holds no digit, so a message naming a file in it can be searched
/// for a PIN (digits) without a false hit from the process id. Removed at scope exit.

#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>

namespace hk::test {

class LetterDir {
 public:
  /// `prefix` starts the folder's name (letters and '_' only, e.g. "hk_pin_command_").
  explicit LetterDir(const std::string& prefix) {
    static int counter = 0;
    std::string tag;
    for (unsigned long v = static_cast<unsigned long>(::getpid()) * 1000 + static_cast<unsigned long>(counter++); v > 0;
         v /= 10)
      tag += static_cast<char>('a' + v % 10);
    path_ = std::filesystem::temp_directory_path() / (prefix + tag);
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~LetterDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  LetterDir(const LetterDir&) = delete;
  LetterDir& operator=(const LetterDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace hk::test
