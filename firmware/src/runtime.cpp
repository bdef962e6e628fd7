// SPDX-License-Identifier: Apache-2.0
// The little C and C++ runtime support a freestanding image needs, written so that none of it
// reaches newlib's stdio, signals or allocator: abort and assert report through semihosting,
// static destructors are never registered (an image never returns to anything that runs them).
#include <cstddef>
#include <cstdlib>
#include <new>

#include "settle/firmware/runtime.hpp"
#include "settle/firmware/semihosting.hpp"
#include "settle/firmware/text.hpp"

extern "C" {

// newlib's abort raises SIGABRT through _kill/_getpid, which a bare board does not have.
void abort() noexcept { settle::firmware::fatal("settle: abort\n", 134); }

// newlib's assert handler prints with fiprintf, which allocates.
[[noreturn]] void __assert_func(const char* file, int line, const char* function,
                                const char* expression) {
  settle::firmware::Text<200> message{};
  message.append("settle: assertion failed: ")
      .append(expression != nullptr ? expression : "?")
      .append(" in ")
      .append(function != nullptr ? function : "?")
      .append(" at ")
      .append(file != nullptr ? file : "?")
      .append(":")
      .append_signed(line)
      .append("\n");
  settle::firmware::fatal(message.view(), 134);
}

void __cxa_pure_virtual() { settle::firmware::fatal("settle: pure virtual call\n", 134); }

// Static objects with destructors register them here; an image ends by exiting the emulator,
// so nothing would ever run them, and newlib's registration table may grow through malloc.
void* __dso_handle{nullptr};
int __aeabi_atexit(void*, void (*)(void*), void*) { return 0; }
int __cxa_atexit(void (*)(void*), void*, void*) { return 0; }

}  // extern "C"

// A class with a virtual destructor has a deleting destructor that names operator delete even
// when no object is ever allocated; defining it here keeps libstdc++'s (and free) out of the
// image. Nothing can reach it: operator new does not link (see no_heap.cpp).
void operator delete(void*) noexcept { settle::firmware::fatal("settle: operator delete\n", 134); }
void operator delete[](void*) noexcept { settle::firmware::fatal("settle: operator delete\n", 134); }
void operator delete(void*, std::size_t) noexcept {
  settle::firmware::fatal("settle: operator delete\n", 134);
}
void operator delete[](void*, std::size_t) noexcept {
  settle::firmware::fatal("settle: operator delete\n", 134);
}
void operator delete(void*, std::align_val_t) noexcept {
  settle::firmware::fatal("settle: operator delete\n", 134);
}
void operator delete[](void*, std::align_val_t) noexcept {
  settle::firmware::fatal("settle: operator delete\n", 134);
}
void operator delete(void*, std::size_t, std::align_val_t) noexcept {
  settle::firmware::fatal("settle: operator delete\n", 134);
}
void operator delete[](void*, std::size_t, std::align_val_t) noexcept {
  settle::firmware::fatal("settle: operator delete\n", 134);
}
