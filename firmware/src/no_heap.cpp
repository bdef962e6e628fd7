// SPDX-License-Identifier: Apache-2.0
// The images link no heap, and this file makes that a link error rather than a convention.
// Every allocation entry point of newlib and of C++ is defined here, each in a section of its
// own named .settle_no_heap.<function>. With --gc-sections a section survives only if something
// the image really uses calls into it, and sections.ld asserts that no .settle_no_heap section
// survived: so a malloc, an operator new or an _sbrk pulled in by any object fails the link, and
// the map file names which entry point was reached. (Defining them here also stops the linker
// from fetching newlib's real allocator, which would otherwise satisfy those references.)
//
// Deliberately no <cstdlib>: these malloc definitions need no declaration to agree with.
#include <cstddef>
#include <new>

namespace {
[[noreturn]] void unreachable() { __builtin_trap(); }
}  // namespace

#define SETTLE_NO_HEAP(name) [[gnu::section(".settle_no_heap." #name)]]

extern "C" {
SETTLE_NO_HEAP(malloc) void* malloc(std::size_t) { unreachable(); }
SETTLE_NO_HEAP(calloc) void* calloc(std::size_t, std::size_t) { unreachable(); }
SETTLE_NO_HEAP(realloc) void* realloc(void*, std::size_t) { unreachable(); }
SETTLE_NO_HEAP(free) void free(void*) { unreachable(); }
SETTLE_NO_HEAP(memalign) void* memalign(std::size_t, std::size_t) { unreachable(); }
SETTLE_NO_HEAP(aligned_alloc) void* aligned_alloc(std::size_t, std::size_t) { unreachable(); }
SETTLE_NO_HEAP(posix_memalign) int posix_memalign(void**, std::size_t, std::size_t) {
  unreachable();
}
// newlib's reentrant variants, which its own stdio and string functions call.
SETTLE_NO_HEAP(_malloc_r) void* _malloc_r(void*, std::size_t) { unreachable(); }
SETTLE_NO_HEAP(_calloc_r) void* _calloc_r(void*, std::size_t, std::size_t) { unreachable(); }
SETTLE_NO_HEAP(_realloc_r) void* _realloc_r(void*, void*, std::size_t) { unreachable(); }
SETTLE_NO_HEAP(_free_r) void _free_r(void*, void*) { unreachable(); }
SETTLE_NO_HEAP(_memalign_r) void* _memalign_r(void*, std::size_t, std::size_t) { unreachable(); }
// The break itself, for anything that grows memory without going through malloc.
SETTLE_NO_HEAP(_sbrk) void* _sbrk(std::ptrdiff_t) { unreachable(); }
SETTLE_NO_HEAP(_sbrk_r) void* _sbrk_r(void*, std::ptrdiff_t) { unreachable(); }
SETTLE_NO_HEAP(sbrk) void* sbrk(std::ptrdiff_t) { unreachable(); }
}

// The replaceable global allocation functions (operator delete lives in runtime.cpp: a
// polymorphic class's deleting destructor names it even when nothing is ever allocated).
SETTLE_NO_HEAP(new) void* operator new(std::size_t) { unreachable(); }
SETTLE_NO_HEAP(new_array) void* operator new[](std::size_t) { unreachable(); }
SETTLE_NO_HEAP(new_nothrow) void* operator new(std::size_t, const std::nothrow_t&) noexcept {
  unreachable();
}
SETTLE_NO_HEAP(new_array_nothrow) void* operator new[](std::size_t, const std::nothrow_t&) noexcept {
  unreachable();
}
SETTLE_NO_HEAP(new_aligned) void* operator new(std::size_t, std::align_val_t) { unreachable(); }
SETTLE_NO_HEAP(new_array_aligned) void* operator new[](std::size_t, std::align_val_t) {
  unreachable();
}
SETTLE_NO_HEAP(new_aligned_nothrow)
void* operator new(std::size_t, std::align_val_t, const std::nothrow_t&) noexcept {
  unreachable();
}
SETTLE_NO_HEAP(new_array_aligned_nothrow)
void* operator new[](std::size_t, std::align_val_t, const std::nothrow_t&) noexcept {
  unreachable();
}
