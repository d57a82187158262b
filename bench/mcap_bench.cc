// the MCAP log (autonomy/log/mcap.h) on 10 s of a run's raw wire traffic:
// 640 Ouster LEGACY LiDAR packets a second (6464 bytes: 16 columns of a
// 16-byte header, 32 pixels of 12 bytes and a status word; 40 % of pixels
// without a return, all zero; the rest a random range of 0.5-100 m in its
// 20 bits, signal, reflectivity and near-IR drawn in their usual spans) and
// 1000 CAN frames a second (16 bytes: id, length, padding, 8 random data
// bytes), in time order: 41.5 MB of messages.
//
// BM_McapWrite/zstd_level:0|1|3: the 10 s written into memory and closed
//   (summary, footer), uncompressed or zstd at level 1 (the default) or 3,
//   in 4 MiB chunks. bytes_per_second
//   counts the messages' bytes; ratio is the file's size over theirs;
//   realtime is simulated seconds per wall second.
// BM_McapWriteFile: the same, zstd level 1, through FileSink to a temporary file.
// BM_McapRead/zstd_level:0|1: every message read back in log-time order, chunk
//   CRCs checked.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "autonomy/log/mcap.h"

namespace {

using namespace paddock::log;

constexpr double kSeconds = 10.0;
constexpr int kColumnsPerPacket = 16, kPixels = 32, kColumns = 1024;
constexpr std::size_t kColumnBytes = 16 + kPixels * 12 + 4;  // 404
constexpr std::size_t kPacketBytes = kColumnsPerPacket * kColumnBytes;  // 6464

struct Traffic {
  struct Item {
    std::uint64_t t;  // ns
    std::uint16_t channel;  // 1 LiDAR, 2 CAN
    std::uint32_t index;    // into lidar or can
  };
  std::vector<std::vector<std::uint8_t>> lidar, can;
  std::vector<Item> order;
  std::size_t bytes = 0;
};

void put(std::uint8_t* p, std::uint64_t v, int n) {
  for (int i = 0; i < n; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}

// 10 s of packets and frames, built once
const Traffic& traffic() {
  static const Traffic tr = [] {
    Traffic t;
    std::mt19937 rng(7);
    std::uniform_int_distribution<int> pct(0, 99);
    std::uniform_int_distribution<std::uint32_t> range(500, 100000), signal(0, 4000), refl(0, 255), nir(0, 3000);
    std::uniform_int_distribution<int> byte(0, 255);
    const std::uint64_t t0 = 1'700'000'000'000'000'000ull;
    const auto packets = static_cast<std::uint32_t>(640 * kSeconds);
    // the LiDAR: 64 packets a rotation, 10 rotations a second
    for (std::uint32_t k = 0; k < packets; ++k) {
      std::vector<std::uint8_t> p(kPacketBytes, 0);
      const std::uint64_t stamp = t0 + k * 1'562'500ull;
      for (int c = 0; c < kColumnsPerPacket; ++c) {
        std::uint8_t* col = p.data() + static_cast<std::size_t>(c) * kColumnBytes;
        const std::uint32_t measurement = (k % 64) * kColumnsPerPacket + static_cast<std::uint32_t>(c);
        put(col, stamp + static_cast<std::uint64_t>(c) * 97'656, 8);
        put(col + 8, measurement, 2);
        put(col + 10, k / 64, 2);
        put(col + 12, measurement * (90112 / kColumns), 4);
        for (int px = 0; px < kPixels; ++px) {
          std::uint8_t* d = col + 16 + px * 12;
          if (pct(rng) < 40) continue;  // no return: all zero
          put(d, range(rng), 4);
          put(d + 4, signal(rng), 2);
          put(d + 6, refl(rng), 2);
          put(d + 8, nir(rng), 2);
        }
        put(col + 16 + kPixels * 12, 0xFFFFFFFFu, 4);
      }
      t.bytes += p.size();
      t.order.push_back({stamp, 1, k});
      t.lidar.push_back(std::move(p));
    }
    // the CAN bus: 1000 frames a second
    const auto frames = static_cast<std::uint32_t>(1000 * kSeconds);
    for (std::uint32_t k = 0; k < frames; ++k) {
      std::vector<std::uint8_t> f(16, 0);
      put(f.data(), 0x100 + k % 12, 4);
      f[4] = 8;
      for (int i = 8; i < 16; ++i) f[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(byte(rng));
      t.bytes += f.size();
      t.order.push_back({t0 + k * 1'000'000ull, 2, k});
      t.can.push_back(std::move(f));
    }
    std::stable_sort(t.order.begin(), t.order.end(), [](const auto& a, const auto& b) { return a.t < b.t; });
    return t;
  }();
  return tr;
}

// the whole 10 s through one writer
void write_run(McapWriter& w) {
  const Traffic& t = traffic();
  const std::uint16_t lidar = w.add_channel(0, "/lidar/packets", "ouster.lidar_packet.legacy");
  const std::uint16_t can = w.add_channel(0, "/can/frames", "paddock.can_frame");
  std::uint32_t seq[2] = {0, 0};
  for (const auto& i : t.order) {
    const auto& m = i.channel == 1 ? t.lidar[i.index] : t.can[i.index];
    w.write(i.channel == 1 ? lidar : can, seq[i.channel - 1]++, i.t, i.t, m.data(), m.size());
  }
  w.close();
}

// zstd at `level`, or uncompressed when it is 0; compressed on the
// caller's thread (the writer's whole work in the benchmark's thread and
// its CPU time, which ./paddock bench compare compares)
McapWriterOptions options(std::int64_t level) {
  McapWriterOptions o;
  o.compression = level > 0 ? Compression::Zstd : Compression::None;
  o.zstd_level = static_cast<int>(level);
  o.background = false;
  return o;
}

void BM_McapWrite(benchmark::State& state) {
  const Traffic& t = traffic();
  std::vector<std::uint8_t> file;
  file.reserve(t.bytes + (t.bytes >> 3));
  for (auto _ : state) {
    file.clear();
    McapWriter w(std::make_unique<MemorySink>(file), options(state.range(0)));
    write_run(w);
    benchmark::DoNotOptimize(file.data());
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * t.bytes));
  state.counters["ratio"] = static_cast<double>(file.size()) / static_cast<double>(t.bytes);
  state.counters["file_MB"] = static_cast<double>(file.size()) / 1e6;
  state.counters["realtime"] =
      benchmark::Counter(kSeconds * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_McapWrite)->ArgName("zstd_level")->Arg(0)->Arg(1)->Arg(3)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_McapWriteFile(benchmark::State& state) {
  const Traffic& t = traffic();
  const std::string path =
      (std::filesystem::temp_directory_path() / ("paddock_mcap_bench_" + std::to_string(::getpid()) + ".mcap")).string();
  for (auto _ : state) {
    McapWriter w(std::make_unique<FileSink>(path), options(1));
    write_run(w);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * t.bytes));
  state.counters["file_MB"] = static_cast<double>(std::filesystem::file_size(path)) / 1e6;
  std::filesystem::remove(path);
}
BENCHMARK(BM_McapWriteFile)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_McapRead(benchmark::State& state) {
  const Traffic& t = traffic();
  std::vector<std::uint8_t> file;
  {
    McapWriter w(std::make_unique<MemorySink>(file), options(state.range(0)));
    write_run(w);
  }
  std::size_t messages = 0;
  for (auto _ : state) {
    McapReader r(std::make_unique<MemorySource>(file.data(), file.size()));
    r.open();
    auto it = r.messages();
    Message m;
    messages = 0;
    while (it.next(m)) {
      benchmark::DoNotOptimize(m.data);
      ++messages;
    }
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * t.bytes));
  state.counters["messages"] = static_cast<double>(messages);
}
BENCHMARK(BM_McapRead)->ArgName("zstd_level")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
