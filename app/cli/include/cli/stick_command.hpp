#pragma once
/// @file stick_command.hpp
/// `haptic-kiosk stick DIR|--device DEV [--json FILE]` (DESIGN.md "Headless runs"): what
/// a USB stick offers, exactly as the kiosk scans it, and what was refused and why.

#include <string>

namespace hk::app {

/// What `haptic-kiosk stick` was asked to do. Exactly one of folder and device is set.
struct StickOptions {
  std::string folder;       ///< a mounted stick or any folder
  std::string device;       ///< a block device (e.g. /dev/sdb1): mounted read-only, scanned, unmounted
  std::string json_path;    ///< write the listing here (atomically); empty: print it on standard output
  std::string config_path;  ///< TOML settings ([stick] limits); empty: defaults
  std::string mount_root;   ///< where --device is mounted; empty: sticks::kDefaultStickMountRoot
};

/// Runs the command: scans (mounting first with --device), probes every PDF's pages in the worker, writes
/// the JSON of stick_listing_json. Returns the exit status: 0 when the scan ran (things refused or a limit
/// reached are in the JSON, not errors).
/// @throws vision::StickError / sticks::StickMountError / AppError (one line) when the folder or
///         device cannot be read or mounted, or the JSON cannot be written.
int run_stick(const StickOptions& options);

}  // namespace hk::app
