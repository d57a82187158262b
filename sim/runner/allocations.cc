#include "sim/runner/allocations.h"

#include <cstdlib>
#include <new>

#if defined(__SANITIZE_ADDRESS__)
#define PADDOCK_NO_ALLOCATION_COUNT 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(memory_sanitizer) || __has_feature(thread_sanitizer)
#define PADDOCK_NO_ALLOCATION_COUNT 1
#endif
#endif

namespace paddock::runner {

#ifdef PADDOCK_NO_ALLOCATION_COUNT

bool allocations_counted() { return false; }
std::uint64_t thread_allocations() { return 0; }

#else

namespace {
// constant-initialised, trivially destructible: no TLS wrapper, safe to
// touch from the first allocation of a thread to its last
thread_local std::uint64_t t_allocations = 0;
}  // namespace

bool allocations_counted() { return true; }
std::uint64_t thread_allocations() { return t_allocations; }

#endif

}  // namespace paddock::runner

#ifndef PADDOCK_NO_ALLOCATION_COUNT

// The replaceable global operator new (C++17 [new.delete]): malloc as
// libstdc++'s own does, a count in front. The default operator delete frees
// with free(), which matches; the nothrow and array forms call these. The
// aligned forms are left to the library (nothing here allocates over-aligned).
void* operator new(std::size_t size) {
  ++paddock::runner::t_allocations;
  if (size == 0) size = 1;
  for (;;) {
    if (void* p = std::malloc(size)) return p;
    std::new_handler h = std::get_new_handler();
    if (h == nullptr) throw std::bad_alloc();
    h();
  }
}

void* operator new[](std::size_t size) { return ::operator new(size); }

#endif
