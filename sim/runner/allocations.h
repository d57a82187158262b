#pragma once
// How many times this thread has allocated from the C++ heap (every
// operator new and new[]: the containers, the strings, std::function's
// captures): the runner's measure of allocations in the loop (summary.json's
// `allocations`, `paddock run --profile`'s column). Counted by this
// program's own replacement of the global operator new, a thread-local
// increment in front of malloc. Not under a sanitizer (ASan and the fuzz
// build bring their own operator new): counted() is false there, and
// thread_allocations() stays 0. C's malloc (Embree's, Eigen's aligned
// buffers) is not counted.
#include <cstdint>

namespace paddock::runner {

bool allocations_counted();
std::uint64_t thread_allocations();

}  // namespace paddock::runner
