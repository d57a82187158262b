// the benchmark binary's entry point (each bench/*_bench.cc registers its own)
#include <benchmark/benchmark.h>

BENCHMARK_MAIN();
