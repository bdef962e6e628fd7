// SPDX-License-Identifier: Apache-2.0
// The Linux loop's PM QoS request: what it writes, and that it holds the file exactly as long as
// it lives (the kernel withdraws the request when the file is closed).
#include <dirent.h>
#include <stdlib.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>
#include <vector>

#include "settle/runtime/linux/periodic.hpp"

namespace {

using settle::runtime::linux_rt::CpuLatencyRequest;

// How many of this process's descriptors are open on `path`.
int open_descriptors_on(const std::string& path) {
  int n = 0;
  DIR* d = opendir("/proc/self/fd");
  if (d == nullptr) return -1;
  while (const dirent* e = readdir(d)) {
    std::array<char, 4096> target{};
    const std::string link = std::string{"/proc/self/fd/"} + e->d_name;
    const ssize_t len = readlink(link.c_str(), target.data(), target.size() - 1);
    if (len > 0 && std::string(target.data(), static_cast<std::size_t>(len)) == path) ++n;
  }
  closedir(d);
  return n;
}

std::vector<unsigned char> contents(const std::string& path) {
  std::ifstream f{path, std::ios::binary};
  return {std::istreambuf_iterator<char>{f}, std::istreambuf_iterator<char>{}};
}

class TempFile {
 public:
  TempFile() {
    std::string templ = ::testing::TempDir() + "pm_qos_XXXXXX";
    const int fd = mkstemp(templ.data());
    if (fd >= 0) close(fd);
    path = templ;
  }
  ~TempFile() { unlink(path.c_str()); }
  std::string path;
};

TEST(CpuLatencyRequest, WritesTheLatencyAsFourBinaryBytesAndHoldsTheFileUntilDestroyed) {
  TempFile file;
  std::optional<CpuLatencyRequest> request;
  request.emplace(0, file.path.c_str());
  ASSERT_TRUE(request->held()) << request->error();
  EXPECT_EQ(request->error(), "");
  EXPECT_EQ(contents(file.path), (std::vector<unsigned char>{0, 0, 0, 0}));
  EXPECT_EQ(open_descriptors_on(file.path), 1);
  request.reset();
  EXPECT_EQ(open_descriptors_on(file.path), 0);
}

TEST(CpuLatencyRequest, AnyLatencyIsWrittenInTheKernelsBinaryForm) {
  TempFile file;
  const CpuLatencyRequest request{20, file.path.c_str()};
  ASSERT_TRUE(request.held());
  EXPECT_EQ(contents(file.path), (std::vector<unsigned char>{20, 0, 0, 0}));
}

TEST(CpuLatencyRequest, AFileThatCannotBeOpenedIsReportedNotFatal) {
  const CpuLatencyRequest request{0, "/nonexistent/cpu_dma_latency"};
  EXPECT_FALSE(request.held());
  EXPECT_EQ(request.error(), "No such file or directory");
}

}  // namespace
