#pragma once
/// @file unique_fd.hpp
/// A file descriptor closed at the end of its scope (a stick's scan, its block device).

#include <unistd.h>

namespace hk {

/// Owns one file descriptor (−1: none) and closes it when destroyed. Not copyable.
class UniqueFd {
 public:
  explicit UniqueFd(int fd = -1) : fd_(fd) {}
  ~UniqueFd() {
    if (fd_ >= 0) ::close(fd_);
  }
  UniqueFd(const UniqueFd&) = delete;
  UniqueFd& operator=(const UniqueFd&) = delete;
  int get() const { return fd_; }
  bool ok() const { return fd_ >= 0; }

 private:
  int fd_;
};

}  // namespace hk
