// SPDX-License-Identifier: Apache-2.0
// Deliberately allocating image: the link of each variant must fail (firmware/CMakeLists.txt
// registers the failed link as the passing test). Each variant reaches the heap another way.
#include <cstdlib>
#include <vector>

#include "settle/firmware/runtime.hpp"

#if defined(SETTLE_PROBE_SBRK)
extern "C" void* _sbrk(int);
#endif

namespace {
// Keeps the allocation observable, so the compiler cannot elide it.
void* volatile keep{nullptr};
}  // namespace

int settle::firmware::image_main() {
#if defined(SETTLE_PROBE_MALLOC)
  keep = std::malloc(64);
#elif defined(SETTLE_PROBE_NEW)
  std::vector<int> values{};
  values.push_back(1);
  keep = values.data();
#elif defined(SETTLE_PROBE_SBRK)
  keep = _sbrk(64);
#else
#error "choose a SETTLE_PROBE_* variant"
#endif
  return 0;
}
