#pragma once
// one libFuzzer target per parser or decoder (fuzz/<name>_fuzz.cc). Each
// defines LLVMFuzzerTestOneInput: the input goes through the parser the way
// a file or a packet from outside would, and the errors the parser promises
// for bad input (its documented exception types, its counters) are caught
// there. Anything else escapes: another exception type, a crash, a sanitizer
// report, a hang. Built two ways: with clang's libFuzzer in build-fuzz/
// (./paddock fuzz TARGET) and, in every build, as fuzz_replay_<name> with
// fuzz/replay_main.cc, which runs the committed corpus
// (fuzz/corpus/<name>/: seeds from the repo's own files and every input a
// fuzzer ever found a fault with) as a ctest regression test.
#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace paddock::fuzz {

// the repository's root (the seeds and the shipped sensor files)
#ifndef PADDOCK_SOURCE_DIR
#error "PADDOCK_SOURCE_DIR must be defined"
#endif
inline std::string source_dir() { return PADDOCK_SOURCE_DIR; }

}  // namespace paddock::fuzz
