// The kiosk's stick service without CAP_SYS_ADMIN: it mounts through the mount helper.
// A fake helper (a shell script named by $HK_STICK_HELPER) answers as hk-stick-mount does, with a folder of
// documents standing for the mounted stick, so this runs without root and mounts nothing. When the test
// runs as root, a forked child first drops CAP_SYS_ADMIN, so the service has to choose the helper.

#include <gtest/gtest.h>

#include <linux/capability.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <thread>

#include "child_process.hpp"
#include "pictures/stick_service.hpp"
#include "test_paths.hpp"

namespace hk::app {
namespace {

namespace fs = std::filesystem;

const fs::path kData = HK_TEST_DATA_DIR;

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Drops CAP_SYS_ADMIN from this (single-threaded) process's effective, permitted and inheritable sets.
bool drop_sys_admin() {
  __user_cap_header_struct header{_LINUX_CAPABILITY_VERSION_3, 0};
  __user_cap_data_struct data[_LINUX_CAPABILITY_U32S_3]{};
  if (::syscall(SYS_capget, &header, data) != 0) return false;
  const unsigned bit = 1u << (CAP_SYS_ADMIN % 32);
  data[CAP_SYS_ADMIN / 32].effective &= ~bit;
  data[CAP_SYS_ADMIN / 32].permitted &= ~bit;
  data[CAP_SYS_ADMIN / 32].inheritable &= ~bit;
  return ::syscall(SYS_capset, &header, data) == 0;
}

/// Runs `body` in a forked child (which has no CAP_SYS_ADMIN); returns what it reported ("" = passed).
std::string in_child_without_sys_admin(const std::function<std::string()>& body) {
  return test::run_in_child(
      [&]() -> std::string {
        if (!drop_sys_admin() || sticks::have_mount_capability()) return "cannot drop CAP_SYS_ADMIN";
        return body();
      },
      "pipe or fork failed");
}

/// The first news within 20 s.
std::optional<StickNews> next_news(StickService& svc) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (std::chrono::steady_clock::now() < deadline) {
    std::vector<StickNews> n = svc.poll_news();
    if (!n.empty()) return n.front();
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return std::nullopt;
}

TEST(StickServiceHelper, WithoutTheCapabilityTheHelperMountsAndUnmounts) {
  char tmpl[] = "/tmp/hk_service_helper_XXXXXX";
  ASSERT_NE(::mkdtemp(tmpl), nullptr);
  const fs::path dir = tmpl;
  const fs::path stick = dir / "stick";  // what the fake helper says it mounted
  fs::create_directories(stick);
  fs::copy_file(kData / "images" / "silhouette_3.png", stick / "shape.png");
  const fs::path log = dir / "calls.log";
  const fs::path helper = dir / "hk-stick-mount";
  std::ofstream(helper) << "#!/bin/sh\necho \"$*\" >> '" << log.string() << "'\n"
                        << "case \"$1\" in\n"
                        << "  mount) if [ \"$2\" = /dev/sdz9 ]; then echo \"hk-stick-mount: stick '$2': its filesystem "
                           "(swap) is not one the kiosk reads\" >&2; exit 1; fi\n"
                        << "         echo \"mounted vfat at " << stick.string() << " from $2\" ;;\n"
                        << "  unmount) echo \"unmounted " << stick.string() << "\" ;;\n"
                        << "esac\n";
  fs::permissions(helper, fs::perms(0755));

  const std::string result = in_child_without_sys_admin([&]() -> std::string {
    ::setenv("HK_STICK_HELPER", helper.c_str(), 1);
    auto events = std::make_unique<sticks::FakeBlockEventSource>();
    sticks::FakeBlockEventSource* fake = events.get();
    StickService svc(config::Settings{}, std::move(events), (dir / "mnt").string());
    if (svc.mounter() != sticks::StickMounter::Helper || !svc.can_mount())
      return "the service did not choose the helper";

    fake->push({sticks::BlockEvent::Action::Add, "/dev/sdz1", ""});
    std::optional<StickNews> n = next_news(svc);
    if (!n || n->kind != StickNews::Kind::Inserted)
      return "insert: no Inserted news" + (n ? " (" + n->reason + ")" : std::string());
    if (n->documents.size() != 1)
      return "insert: expected shape.png, got " + std::to_string(n->documents.size()) + " documents";
    fake->push({sticks::BlockEvent::Action::Remove, "/dev/sdz1", ""});
    n = next_news(svc);
    if (!n || n->kind != StickNews::Kind::Removed) return "remove: no Removed news";

    // The helper's refusal reaches the visitor as the reason, without the device's name.
    fake->push({sticks::BlockEvent::Action::Add, "/dev/sdz9", ""});
    n = next_news(svc);
    if (!n || n->kind != StickNews::Kind::Refused) return "refused stick: no Refused news";
    if (n->reason != "its filesystem (swap) is not one the kiosk reads")
      return "refused stick: reason '" + n->reason + "'";
    return "";
  });
  EXPECT_EQ(result, "");
  // Mounted at slot 0, unmounted when taken out; the refused stick got the next slot.
  EXPECT_EQ(slurp(log), "mount /dev/sdz1 0\nunmount 0\nmount /dev/sdz9 1\n");
  std::error_code ec;
  fs::remove_all(dir, ec);
}

}  // namespace
}  // namespace hk::app
