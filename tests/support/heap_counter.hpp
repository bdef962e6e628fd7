// SPDX-License-Identifier: Apache-2.0
#pragma once
// Counts every heap allocation of a test binary: replaces malloc and the global operator new.
// Include it in exactly one source file of the binary (it defines those functions) and read
// g_allocations before and after what must not allocate.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>

inline std::atomic<std::uint64_t> g_allocations{0};

// malloc too (Eigen's dynamic matrices allocate with it), as tests/runtime/test_no_alloc.cpp
// does; not under AddressSanitizer, which owns malloc there (operator new still counts).
#ifndef __SANITIZE_ADDRESS__
extern "C" void* __libc_malloc(std::size_t);  // glibc's own allocator, beneath our hook
extern "C" void* malloc(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(n);
}
#endif
void* operator new(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  void* p = std::malloc(n == 0 ? 1 : n);
  if (p == nullptr) throw std::bad_alloc{};
  return p;
}
// GCC cannot see that this operator new allocates with malloc.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop
