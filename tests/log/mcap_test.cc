// the MCAP writer and readers (autonomy/log/mcap.h) against the specification
// (https://mcap.dev/spec): a round trip of a run's traffic, the byte layout
// of a tiny file parsed here by hand, the official TypeScript reader
// (@mcap/core under node, tests/log/validate_mcap.mjs), bad input of every
// kind, and the file sink's atomic close.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <ostream>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "autonomy/log/mcap.h"

// the compression as test names and messages show it
namespace paddock::log {
void PrintTo(Compression c, std::ostream* os) { *os << (c == Compression::Zstd ? "zstd" : "none"); }
}  // namespace paddock::log

namespace {

namespace fs = std::filesystem;
using namespace paddock::log;
using Bytes = std::vector<std::uint8_t>;

// ------------------------------------------------------------ helpers

// a message as written (and as read back)
struct Written {
  std::uint16_t channel = 0;
  std::uint32_t sequence = 0;
  std::uint64_t log_time = 0, publish_time = 0;
  Bytes data;
  bool operator==(const Written& o) const {
    return channel == o.channel && sequence == o.sequence && log_time == o.log_time &&
           publish_time == o.publish_time && data == o.data;
  }
};

Written copy(const Message& m) {
  return {m.channel_id, m.sequence, m.log_time, m.publish_time, Bytes(m.data, m.data + m.size)};
}

// the channels of a run: raw wire messages and JSON in Foxglove's schemas
struct TopicSpec {
  std::string topic, encoding, schema_name;
};
const std::vector<TopicSpec> kTopics = {
    {"/lidar/packets", "ouster.lidar_packet.legacy", ""},
    {"/can/frames", "paddock.can_frame", ""},
    {"/camera/image/compressed", "json", "foxglove.CompressedImage"},
    {"/stack/pose", "json", "foxglove.PoseInFrame"},
    {"/diagnostics", "json", "foxglove.Log"},  // no messages: counted as a channel only
};

// a run's traffic in arrival (write) order: LiDAR packets at 640 Hz, CAN at
// 1 kHz, poses at 100 Hz (some at the same instant as a CAN frame), camera
// frames at 20 Hz stamped at exposure, 30 ms before they arrive: log times
// are not monotonic in write order
std::vector<Written> make_run(double seconds, std::uint32_t seed, std::size_t lidar_bytes = 6464) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> byte(0, 255);
  const std::uint64_t t0 = 1'700'000'000'000'000'000ull;
  struct Item {
    std::uint64_t arrival;
    Written w;
  };
  std::vector<Item> items;
  auto payload = [&](std::size_t n, bool sparse) {
    Bytes b(n);
    for (auto& x : b) x = sparse && byte(rng) < 100 ? 0 : static_cast<std::uint8_t>(byte(rng));
    return b;
  };
  const auto horizon = static_cast<std::uint64_t>(seconds * 1e9);
  std::uint32_t seq[5] = {};
  for (std::uint64_t t = 0; t < horizon; t += 1'562'500) {
    items.push_back({t0 + t, {1, seq[0]++, t0 + t, t0 + t, payload(lidar_bytes, true)}});
  }
  for (std::uint64_t t = 0; t < horizon; t += 1'000'000) {
    items.push_back({t0 + t + 1, {2, seq[1]++, t0 + t, t0 + t + 1, payload(16, false)}});
  }
  for (std::uint64_t t = 40'000'000; t < horizon; t += 50'000'000) {
    const std::string json = "{\"timestamp\":{\"sec\":" + std::to_string((t0 + t) / 1'000'000'000) +
                             "},\"frame_id\":\"camera\",\"format\":\"jpeg\",\"data\":\"" +
                             std::string(2000 + (t / 50'000'000) % 500, 'A') + "\"}";
    items.push_back({t0 + t + 30'000'000, {3, seq[2]++, t0 + t, t0 + t, Bytes(json.begin(), json.end())}});
  }
  for (std::uint64_t t = 0; t < horizon; t += 10'000'000) {
    const std::string json = "{\"frame_id\":\"map\",\"pose\":{\"position\":{\"x\":" + std::to_string(t % 977) + "}}}";
    items.push_back({t0 + t + 2, {4, seq[3]++, t0 + t, t0 + t, Bytes(json.begin(), json.end())}});
  }
  std::stable_sort(items.begin(), items.end(), [](const Item& a, const Item& b) { return a.arrival < b.arrival; });
  std::vector<Written> out;
  for (auto& i : items) out.push_back(std::move(i.w));
  return out;
}

// writes the channels (and their schemas) and `messages` into a file in memory
Bytes write_file(const std::vector<Written>& messages, McapWriterOptions options) {
  Bytes bytes;
  McapWriter w(std::make_unique<MemorySink>(bytes), options);
  for (const TopicSpec& t : kTopics) {
    std::uint16_t schema = 0;
    if (!t.schema_name.empty()) {
      schema = w.add_schema(t.schema_name, "jsonschema", "{\"title\":\"" + t.schema_name + "\",\"type\":\"object\"}");
    }
    w.add_channel(schema, t.topic, t.encoding, {{"source", "paddock"}, {"topic", t.topic}});
  }
  for (const Written& m : messages) {
    w.write(m.channel, m.sequence, m.log_time, m.publish_time, m.data.data(), m.data.size());
  }
  w.close();
  return bytes;
}

McapWriterOptions options_for(Compression c, std::uint64_t chunk_size) {
  McapWriterOptions o;
  o.compression = c;
  o.chunk_size = chunk_size;
  return o;
}

std::vector<Written> read_all(McapReader& r, const ReadOptions& opt = {}) {
  std::vector<Written> out;
  auto it = r.messages(opt);
  Message m;
  while (it.next(m)) out.push_back(copy(m));
  return out;
}

std::unique_ptr<McapReader> open_reader(const Bytes& bytes) {
  auto r = std::make_unique<McapReader>(std::make_unique<MemorySource>(bytes));
  r->open();
  return r;
}

// what a stream reader recovers, and how it stopped
struct Streamed {
  std::vector<Written> messages;
  StreamStatus status;
};
Streamed stream_all(const std::uint8_t* data, std::size_t n, bool validate = true) {
  McapStreamReader s(std::make_unique<MemorySource>(data, n), validate);
  Streamed out;
  Message m;
  while (s.next(m)) out.messages.push_back(copy(m));
  out.status = s.status();
  return out;
}

// the log-time order the reader promises: by log time, equal times in write order
std::vector<Written> by_log_time(std::vector<Written> v) {
  std::stable_sort(v.begin(), v.end(), [](const Written& a, const Written& b) { return a.log_time < b.log_time; });
  return v;
}

// little-endian fields read here by hand, apart from the library
std::uint16_t le16(const Bytes& b, std::size_t at) { return static_cast<std::uint16_t>(b.at(at) | (b.at(at + 1) << 8)); }
std::uint32_t le32(const Bytes& b, std::size_t at) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | b.at(at + static_cast<std::size_t>(i));
  return v;
}
std::uint64_t le64(const Bytes& b, std::size_t at) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | b.at(at + static_cast<std::size_t>(i));
  return v;
}
void put64(Bytes& b, std::size_t at, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) b.at(at + static_cast<std::size_t>(i)) = static_cast<std::uint8_t>(v >> (8 * i));
}
void put32(Bytes& b, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b.at(at + static_cast<std::size_t>(i)) = static_cast<std::uint8_t>(v >> (8 * i));
}
std::string str_at(const Bytes& b, std::size_t at) {
  const std::uint32_t n = le32(b, at);
  return std::string(b.begin() + static_cast<std::ptrdiff_t>(at + 4), b.begin() + static_cast<std::ptrdiff_t>(at + 4 + n));
}

// a bitwise CRC-32 (IEEE, reflected 0xEDB88320), the textbook definition
std::uint32_t ref_crc32(const std::uint8_t* p, std::size_t n) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < n; ++i) {
    c ^= p[i];
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? (c >> 1) ^ 0xEDB88320u : c >> 1;
  }
  return ~c;
}

// the top-level records of a file, walked by hand: (offset, opcode, content length)
struct Rec {
  std::size_t at;
  std::uint8_t op;
  std::uint64_t len;
};
std::vector<Rec> walk(const Bytes& b) {
  std::vector<Rec> out;
  std::size_t at = 8;
  while (at + 9 <= b.size() - 8) {
    out.push_back({at, b[at], le64(b, at + 1)});
    at += 9 + static_cast<std::size_t>(out.back().len);
  }
  EXPECT_EQ(at, b.size() - 8) << "the records do not end at the trailing magic";
  return out;
}

// messages per chunk, from the Message Index records the chunk indexes point to
std::vector<std::pair<std::uint64_t, std::uint64_t>> chunk_ends_and_counts(const Bytes& b) {
  auto r = open_reader(b);
  std::vector<std::pair<std::uint64_t, std::uint64_t>> out;
  for (const ChunkIndex& c : r->chunk_indexes()) {
    std::uint64_t count = 0;
    for (const auto& [ch, off] : c.message_index_offsets) {
      EXPECT_EQ(b.at(off), 0x07);
      EXPECT_EQ(le16(b, off + 9), ch);
      count += le32(b, off + 11) / 16;
    }
    out.emplace_back(c.chunk_start_offset + c.chunk_length, count);
  }
  return out;
}

// the file with one field of the Chunk Index of the chunk at `chunk` changed
// (`field`: bytes into the record's content), the summary CRC made right again
Bytes with_chunk_index_field(const Bytes& bytes, std::uint64_t chunk, std::size_t field, std::uint64_t value) {
  Bytes b = bytes;
  const std::size_t footer = b.size() - 37;
  const std::size_t summary = static_cast<std::size_t>(le64(b, footer + 9));
  std::size_t at = summary;
  while (b.at(at) != 0x08 || le64(b, at + 9 + 16) != chunk) at += 9 + static_cast<std::size_t>(le64(b, at + 1));
  put64(b, at + 9 + field, value);
  put32(b, footer + 25, ref_crc32(b.data() + summary, footer + 25 - summary));
  return b;
}

// a folder of its own per test (ctest runs tests side by side), removed
// with everything in it when the test ends, failed or not
struct TestDir {
  fs::path path;
  TestDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string(info->test_suite_name()) + "_" + info->name();
    std::replace(name.begin(), name.end(), '/', '_');
    path = fs::temp_directory_path() / ("paddock_mcap_" + std::to_string(::getpid()) + "_" + name);
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TestDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  TestDir(const TestDir&) = delete;
  TestDir& operator=(const TestDir&) = delete;
};

void save(const fs::path& p, const Bytes& b) {
  std::ofstream f(p, std::ios::binary);
  f.write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
}

class Compressions : public ::testing::TestWithParam<Compression> {};
std::string compression_label(const ::testing::TestParamInfo<Compression>& p) {
  return p.param == Compression::Zstd ? "zstd" : "none";
}

// ------------------------------------------------------------ CRC-32

TEST(Crc32, MatchesTheStandardCheckValueAndTheBitwiseDefinition) {
  const std::string check = "123456789";
  EXPECT_EQ(crc32(check.data(), check.size()), 0xCBF43926u);  // the CRC-32/ISO-HDLC check value
  EXPECT_EQ(crc32(nullptr, 0), 0u);
  std::mt19937 rng(3);
  Bytes data(100'003);
  for (auto& x : data) x = static_cast<std::uint8_t>(rng());
  for (std::size_t n : {std::size_t{1}, std::size_t{7}, std::size_t{8}, std::size_t{9}, std::size_t{63}, data.size()}) {
    EXPECT_EQ(crc32(data.data(), n), ref_crc32(data.data(), n)) << n;
  }
  // chained over two pieces: the CRC of the whole
  EXPECT_EQ(crc32(data.data() + 501, data.size() - 501, crc32(data.data(), 501)), ref_crc32(data.data(), data.size()));
  // every short length at every alignment (where an implementation's word
  // and block steps begin and end)
  for (std::size_t at = 0; at < 16; ++at) {
    for (std::size_t n = 0; n <= 300; ++n) EXPECT_EQ(crc32(data.data() + at, n), ref_crc32(data.data() + at, n)) << at << " " << n;
  }
}

// ------------------------------------------------------------ round trip

TEST_P(Compressions, RoundTripGivesBackWhatWasWrittenWithItsStatistics) {
  const std::vector<Written> run = make_run(0.5, 11);
  McapWriterOptions opt = options_for(GetParam(), 256 << 10);
  opt.profile = "paddock-test";
  Bytes bytes;
  Statistics written_stats;
  {
    McapWriter w(std::make_unique<MemorySink>(bytes), opt);
    for (const TopicSpec& t : kTopics) {
      const std::uint16_t s = t.schema_name.empty() ? 0 : w.add_schema(t.schema_name, "jsonschema", "{\"title\":\"" + t.schema_name + "\"}");
      w.add_channel(s, t.topic, t.encoding, {{"topic", t.topic}});
    }
    for (const Written& m : run) w.write(m.channel, m.sequence, m.log_time, m.publish_time, m.data.data(), m.data.size());
    w.write_metadata("run", {{"scenario", "fsg_2023_trackdrive"}, {"seed", "1"}});
    Attachment a;
    a.log_time = 5;
    a.name = "scenario.ini";
    a.media_type = "text/plain";
    a.data = {'[', 's', 'i', 'm', ']'};
    w.write_attachment(a);
    w.close();
    written_stats = w.statistics();
  }
  auto r = open_reader(bytes);

  // the Header, schemas and channels as written
  EXPECT_EQ(r->header().profile, "paddock-test");
  EXPECT_EQ(r->header().library, "paddock");
  ASSERT_EQ(r->channels().size(), kTopics.size());
  ASSERT_EQ(r->schemas().size(), 3u);
  for (std::size_t i = 0; i < kTopics.size(); ++i) {
    const Channel& c = r->channels().at(static_cast<std::uint16_t>(i + 1));
    EXPECT_EQ(c.topic, kTopics[i].topic);
    EXPECT_EQ(c.message_encoding, kTopics[i].encoding);
    EXPECT_EQ(c.metadata, (KeyValues{{"topic", kTopics[i].topic}}));
    if (kTopics[i].schema_name.empty()) {
      EXPECT_EQ(c.schema_id, 0);
    } else {
      const Schema& s = r->schemas().at(c.schema_id);
      EXPECT_EQ(s.name, kTopics[i].schema_name);
      EXPECT_EQ(s.encoding, "jsonschema");
      const std::string text = "{\"title\":\"" + kTopics[i].schema_name + "\"}";
      EXPECT_EQ(s.data, Bytes(text.begin(), text.end()));
    }
  }

  // the Statistics against counts made here
  std::map<std::uint16_t, std::uint64_t> per_channel;
  std::uint64_t lo = ~0ull, hi = 0;
  for (const Written& m : run) {
    ++per_channel[m.channel];
    lo = std::min(lo, m.log_time);
    hi = std::max(hi, m.log_time);
  }
  ASSERT_TRUE(r->statistics().has_value());
  const Statistics& s = *r->statistics();
  EXPECT_EQ(s.message_count, run.size());
  EXPECT_EQ(s.channel_message_counts, per_channel);
  EXPECT_EQ(s.channel_count, kTopics.size());
  EXPECT_EQ(s.schema_count, 3u);
  EXPECT_EQ(s.message_start_time, lo);
  EXPECT_EQ(s.message_end_time, hi);
  EXPECT_EQ(s.metadata_count, 1u);
  EXPECT_EQ(s.attachment_count, 1u);
  EXPECT_EQ(s.chunk_count, r->chunk_indexes().size());
  EXPECT_GT(s.chunk_count, 4u);  // several chunks: 2.2 MB of records in 256 KiB chunks
  EXPECT_EQ(written_stats.message_count, s.message_count);
  for (const ChunkIndex& c : r->chunk_indexes()) EXPECT_EQ(c.compression, compression_name(GetParam()));

  // messages in log-time order (equal times in write order), and in file order
  const std::vector<Written> got = read_all(*r);
  ASSERT_EQ(got.size(), run.size());
  EXPECT_TRUE(got == by_log_time(run));
  EXPECT_FALSE(run == by_log_time(run)) << "the run should have log times out of write order";
  ReadOptions file_order;
  file_order.order = Order::File;
  EXPECT_TRUE(read_all(*r, file_order) == run);

  // a [start, end) window and a topic filter
  ReadOptions window;
  window.start = lo + 100'000'000;
  window.end = lo + 200'000'000;
  window.topics = {"/can/frames", "/camera/image/compressed"};
  std::vector<Written> expected;
  for (const Written& m : by_log_time(run)) {
    if (m.log_time >= window.start && m.log_time < window.end && (m.channel == 2 || m.channel == 3)) {
      expected.push_back(m);
    }
  }
  ASSERT_GT(expected.size(), 100u);
  EXPECT_TRUE(read_all(*r, window) == expected);
  window.end = window.start;
  EXPECT_TRUE(read_all(*r, window).empty());

  // the data section's CRC, the metadata and the attachment
  EXPECT_NE(r->data_section_crc(), 0u);
  EXPECT_NO_THROW(r->verify_data_crc());
  const auto md = r->read_metadata();
  ASSERT_EQ(md.size(), 1u);
  EXPECT_EQ(md[0].name, "run");
  EXPECT_EQ(md[0].metadata.at("scenario"), "fsg_2023_trackdrive");
  const auto at = r->read_attachments();
  ASSERT_EQ(at.size(), 1u);
  EXPECT_EQ(at[0].name, "scenario.ini");
  EXPECT_EQ(at[0].data, (Bytes{'[', 's', 'i', 'm', ']'}));

  // the streaming reader: the whole file, in file order
  const Streamed st = stream_all(bytes.data(), bytes.size());
  EXPECT_TRUE(st.status.complete) << st.status.error;
  EXPECT_FALSE(st.status.stopped);
  EXPECT_TRUE(st.status.data_end);
  EXPECT_EQ(st.status.offset, bytes.size());
  EXPECT_EQ(st.status.chunks, s.chunk_count);
  EXPECT_EQ(st.status.messages, run.size());
  EXPECT_TRUE(st.messages == run);
}

INSTANTIATE_TEST_SUITE_P(Mcap, Compressions, ::testing::Values(Compression::None, Compression::Zstd),
                         compression_label);

TEST(McapWriter, AnEmptyFileIsValidAndItsIdsAreChecked) {
  Bytes bytes;
  McapWriter w(std::make_unique<MemorySink>(bytes));
  EXPECT_THROW(w.add_channel(1, "/x", "json"), std::invalid_argument);  // no schema 1 yet
  EXPECT_THROW(w.write(1, 0, 0, 0, nullptr, 0), std::invalid_argument);  // no channel 1 yet
  w.close();
  EXPECT_THROW(w.add_schema("a", "", ""), std::logic_error);
  auto r = open_reader(bytes);
  EXPECT_EQ(r->statistics()->message_count, 0u);
  EXPECT_EQ(r->statistics()->message_start_time, 0u);
  EXPECT_TRUE(r->chunk_indexes().empty());
  EXPECT_TRUE(read_all(*r).empty());
  EXPECT_TRUE(stream_all(bytes.data(), bytes.size()).status.complete);
}

// ------------------------------------------------------------ byte layout

TEST(McapLayout, ATinyFileHasTheSpecificationsBytes) {
  Bytes b;
  {
    McapWriterOptions o;
    o.profile = "x";
    o.library = "lib";
    o.compression = Compression::None;
    McapWriter w(std::make_unique<MemorySink>(b), o);
    const std::uint16_t s = w.add_schema("S", "jsonschema", "{}");
    const std::uint16_t c = w.add_channel(s, "/t", "json", {{"k", "v"}});
    w.write(c, 7, 300, 301, std::string("{\"a\":1}"));
    w.write(c, 8, 200, 202, std::string("{}"));
    w.close();
  }
  // "Magic" at both ends
  const Bytes magic = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
  ASSERT_GT(b.size(), 100u);
  EXPECT_EQ(Bytes(b.begin(), b.begin() + 8), magic);
  EXPECT_EQ(Bytes(b.end() - 8, b.end()), magic);
  // "Header (op=0x01)": profile, library
  EXPECT_EQ(b[8], 0x01);
  EXPECT_EQ(le64(b, 9), 4u + 1 + 4 + 3);
  EXPECT_EQ(str_at(b, 17), "x");
  EXPECT_EQ(str_at(b, 22), "lib");
  // the records in order: data section, summary, summary offsets, footer
  const std::vector<Rec> recs = walk(b);
  std::vector<int> ops;
  for (const Rec& r : recs) ops.push_back(r.op);
  EXPECT_EQ(ops, (std::vector<int>{0x01, 0x03, 0x04, 0x06, 0x07, 0x0F,  // Header Schema Channel Chunk MessageIndex DataEnd
                                   0x03, 0x04, 0x0B, 0x08,              // summary: Schema Channel Statistics ChunkIndex
                                   0x0E, 0x0E, 0x0E, 0x0E,              // one Summary Offset per group
                                   0x02}));                             // Footer
  // "Schema (op=0x03)": id, name, encoding, data
  const std::size_t schema = recs[1].at + 9;
  EXPECT_EQ(le16(b, schema), 1);
  EXPECT_EQ(str_at(b, schema + 2), "S");
  EXPECT_EQ(str_at(b, schema + 7), "jsonschema");
  EXPECT_EQ(str_at(b, schema + 21), "{}");
  // "Channel (op=0x04)": id, schema_id, topic, message_encoding, metadata map (byte length first)
  const std::size_t channel = recs[2].at + 9;
  EXPECT_EQ(le16(b, channel), 1);
  EXPECT_EQ(le16(b, channel + 2), 1);
  EXPECT_EQ(str_at(b, channel + 4), "/t");
  EXPECT_EQ(str_at(b, channel + 10), "json");
  EXPECT_EQ(le32(b, channel + 18), 4u + 1 + 4 + 1);
  EXPECT_EQ(str_at(b, channel + 22), "k");
  EXPECT_EQ(str_at(b, channel + 27), "v");
  // "Chunk (op=0x06)": start/end times, sizes, CRC of the records, compression "", records
  const std::size_t chunk = recs[3].at + 9;
  EXPECT_EQ(le64(b, chunk), 200u);
  EXPECT_EQ(le64(b, chunk + 8), 300u);
  const std::uint64_t usize = le64(b, chunk + 16);
  EXPECT_EQ(str_at(b, chunk + 28), "");
  EXPECT_EQ(le64(b, chunk + 32), usize);
  const std::size_t records = chunk + 40;
  EXPECT_EQ(usize, 2u * (9 + 22) + 7 + 2);
  EXPECT_EQ(le32(b, chunk + 24), ref_crc32(b.data() + records, usize));
  EXPECT_EQ(recs[3].len, 40 + usize);
  // "Message (op=0x05)" records inside: channel_id, sequence, log_time, publish_time, data
  EXPECT_EQ(b[records], 0x05);
  EXPECT_EQ(le64(b, records + 1), 22u + 7);
  EXPECT_EQ(le16(b, records + 9), 1);
  EXPECT_EQ(le32(b, records + 11), 7u);
  EXPECT_EQ(le64(b, records + 15), 300u);
  EXPECT_EQ(le64(b, records + 23), 301u);
  EXPECT_EQ(std::string(b.begin() + static_cast<std::ptrdiff_t>(records + 31), b.begin() + static_cast<std::ptrdiff_t>(records + 38)), "{\"a\":1}");
  // "Message Index (op=0x07)": channel, then (log_time, offset) pairs into the records
  const std::size_t mi = recs[4].at + 9;
  EXPECT_EQ(le16(b, mi), 1);
  EXPECT_EQ(le32(b, mi + 2), 32u);
  EXPECT_EQ(le64(b, mi + 6), 300u);
  EXPECT_EQ(le64(b, mi + 14), 0u);
  EXPECT_EQ(le64(b, mi + 22), 200u);
  EXPECT_EQ(le64(b, mi + 30), 9u + 22 + 7);
  EXPECT_EQ(b[records + le64(b, mi + 30)], 0x05);
  EXPECT_EQ(le64(b, records + le64(b, mi + 30) + 15), 200u);
  // "Data End (op=0x0F)": the CRC of every byte before it
  EXPECT_EQ(recs[5].len, 4u);
  EXPECT_EQ(le32(b, recs[5].at + 9), ref_crc32(b.data(), recs[5].at));
  // "Statistics (op=0x0B)"
  const std::size_t st = recs[8].at + 9;
  EXPECT_EQ(le64(b, st), 2u);        // message_count
  EXPECT_EQ(le16(b, st + 8), 1);     // schema_count
  EXPECT_EQ(le32(b, st + 10), 1u);   // channel_count
  EXPECT_EQ(le32(b, st + 22), 1u);   // chunk_count
  EXPECT_EQ(le64(b, st + 26), 200u);  // message_start_time
  EXPECT_EQ(le64(b, st + 34), 300u);  // message_end_time
  EXPECT_EQ(le32(b, st + 42), 10u);   // channel_message_counts: one (uint16, uint64)
  EXPECT_EQ(le16(b, st + 46), 1);
  EXPECT_EQ(le64(b, st + 48), 2u);
  // "Chunk Index (op=0x08)": where the chunk and its message index lie
  const std::size_t ci = recs[9].at + 9;
  EXPECT_EQ(le64(b, ci), 200u);
  EXPECT_EQ(le64(b, ci + 8), 300u);
  EXPECT_EQ(le64(b, ci + 16), recs[3].at);
  EXPECT_EQ(le64(b, ci + 24), 9 + recs[3].len);
  EXPECT_EQ(le32(b, ci + 32), 10u);
  EXPECT_EQ(le16(b, ci + 36), 1);
  EXPECT_EQ(le64(b, ci + 38), recs[4].at);
  EXPECT_EQ(le64(b, ci + 46), 9 + recs[4].len);
  EXPECT_EQ(str_at(b, ci + 54), "");
  EXPECT_EQ(le64(b, ci + 58), usize);
  EXPECT_EQ(le64(b, ci + 66), usize);
  // "Summary Offset (op=0x0E)": each group's opcode, start and length
  const std::vector<std::array<std::size_t, 2>> groups = {{0x03, 6}, {0x04, 7}, {0x0B, 8}, {0x08, 9}};
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const std::size_t so = recs[10 + g].at + 9;
    const Rec& target = recs[groups[g][1]];
    EXPECT_EQ(static_cast<std::size_t>(b[so]), groups[g][0]);
    EXPECT_EQ(le64(b, so + 1), target.at);
    EXPECT_EQ(le64(b, so + 9), 9 + target.len);
  }
  // "Footer (op=0x02)": summary_start, summary_offset_start, summary_crc
  const Rec& footer = recs.back();
  EXPECT_EQ(footer.at, b.size() - 8 - 29);
  EXPECT_EQ(footer.len, 20u);
  EXPECT_EQ(le64(b, footer.at + 9), recs[6].at);
  EXPECT_EQ(le64(b, footer.at + 17), recs[10].at);
  EXPECT_EQ(le32(b, footer.at + 25), ref_crc32(b.data() + recs[6].at, footer.at + 25 - recs[6].at));
}

// ------------------------------------------------------------ the official reader

// runs a command, its stdout and stderr together
struct Ran {
  int status = -1;
  std::string out;
};
Ran run_command(const std::string& cmd) {
  Ran r;
  std::FILE* p = ::popen((cmd + " 2>&1").c_str(), "r");
  if (!p) return r;
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, n);
  const int w = ::pclose(p);
  r.status = WIFEXITED(w) ? WEXITSTATUS(w) : -1;
  return r;
}

// node with @mcap/core, as ./paddock test installs it into the build directory
// (the test's working directory); a reason when missing
std::string validator_missing(std::string& modules) {
  modules = (fs::current_path() / "mcap-validator" / "node_modules").string();
  if (run_command("command -v node").status != 0) return "node is not installed";
  if (!fs::exists(fs::path(modules) / "@mcap" / "core")) return "@mcap/core is not installed in " + modules;
  return "";
}

Ran validate(const std::string& modules, const fs::path& file) {
  const std::string script = std::string(PADDOCK_SOURCE_DIR) + "/tests/log/validate_mcap.mjs";
  return run_command("NODE_PATH='" + modules + "' node '" + script + "' '" + file.string() + "'");
}

TEST_P(Compressions, TheOfficialReaderReadsEveryMessage) {
  std::string modules;
  const std::string missing = validator_missing(modules);
  ASSERT_EQ(missing, "") << "the official MCAP reader is needed: run ./paddock test, which installs node, npm and "
                            "tests/log/package.json's @mcap/core into <build>/mcap-validator";
  const std::vector<Written> run = make_run(0.3, 5);
  const Bytes bytes = write_file(run, options_for(GetParam(), 128 << 10));
  const TestDir tmp;
  const fs::path& dir = tmp.path;
  const fs::path file = dir / "run.mcap";
  save(file, bytes);

  // the line the script prints, made here from what was written
  std::map<std::string, std::uint64_t> topics;
  std::uint64_t lo = ~0ull, hi = 0;
  for (const Written& m : run) {
    ++topics[kTopics[m.channel - 1u].topic];
    lo = std::min(lo, m.log_time);
    hi = std::max(hi, m.log_time);
  }
  std::set<std::string> schemas;
  for (const TopicSpec& t : kTopics) {
    if (!t.schema_name.empty()) schemas.insert(t.schema_name);
  }
  const std::size_t chunks = open_reader(bytes)->chunk_indexes().size();
  ASSERT_GT(chunks, 3u);
  std::string expected = "{\"messages\":" + std::to_string(run.size()) + ",\"chunks\":" + std::to_string(chunks) +
                         ",\"first_log_time\":" + std::to_string(lo) + ",\"last_log_time\":" + std::to_string(hi) +
                         ",\"schemas\":[";
  for (const std::string& s : schemas) expected += (expected.back() == '[' ? "\"" : ",\"") + s + "\"";
  expected += "],\"topics\":{";
  for (const auto& [t, n] : topics) expected += (expected.back() == '{' ? "\"" : ",\"") + t + "\":" + std::to_string(n);
  expected += "}}\n";

  const Ran ok = validate(modules, file);
  EXPECT_EQ(ok.status, 0) << ok.out;
  EXPECT_EQ(ok.out, expected);

  // and it is no rubber stamp: a flipped bit in a chunk fails it
  Bytes damaged = bytes;
  const ChunkIndex c = open_reader(bytes)->chunk_indexes()[1];
  damaged[c.chunk_start_offset + c.chunk_length / 2] ^= 0x10;
  save(dir / "damaged.mcap", damaged);
  const Ran bad = validate(modules, dir / "damaged.mcap");
  EXPECT_EQ(bad.status, 1) << bad.out;
}

// ------------------------------------------------------------ bad input

// a reader's whole pass over a file: McapError or success, never anything else
void read_or_mcap_error(const Bytes& b, bool* opened = nullptr) {
  try {
    auto r = open_reader(b);
    if (opened) *opened = true;
    read_all(*r);
    ReadOptions f;
    f.order = Order::File;
    f.validate_crcs = false;
    read_all(*r, f);
    r->verify_data_crc();
    r->read_metadata();
    r->read_attachments();
  } catch (const McapError&) {
  }
}

TEST_P(Compressions, ATruncatedFileIsAnErrorAndStreamsUpToItsLastWholeChunk) {
  const std::vector<Written> run = make_run(0.1, 7, 1500);
  const Bytes bytes = write_file(run, options_for(GetParam(), 16 << 10));
  const auto chunks = chunk_ends_and_counts(bytes);
  ASSERT_GT(chunks.size(), 5u);
  std::size_t cuts = 0;
  for (std::size_t cut = 0; cut < bytes.size(); cut += 97, ++cuts) {
    const Bytes part(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(cut));
    // the indexed reader: a clear error (the trailing magic or the size)
    try {
      open_reader(part);
      ADD_FAILURE() << "a file cut at " << cut << " opened";
    } catch (const McapError& e) {
      EXPECT_NE(std::string(e.what()).find("mcap: byte"), std::string::npos);
    }
    // the stream: the messages of every Chunk record wholly before the cut, in order
    std::uint64_t expected = 0;
    for (const auto& [end, count] : chunks) {
      if (end <= cut) expected += count;
    }
    const Streamed s = stream_all(part.data(), part.size());
    EXPECT_FALSE(s.status.complete);
    EXPECT_TRUE(s.status.stopped);
    EXPECT_FALSE(s.status.error.empty());
    EXPECT_LE(s.status.offset, cut);
    ASSERT_EQ(s.messages.size(), expected) << "cut at " << cut << ": " << s.status.error;
    EXPECT_TRUE(std::equal(s.messages.begin(), s.messages.end(), run.begin())) << cut;
  }
  EXPECT_GT(cuts, 100u);
}

// the compressing thread changes nothing in the file: the same bytes as
// compressing on the caller's thread, with records written between the
// chunks (a schema, a channel, metadata, an attachment) in their places;
// unclosed, the .tmp holds every whole chunk either way
TEST_P(Compressions, ABackgroundCompressionWritesTheSameBytes) {
  const std::vector<Written> run = make_run(0.4, 11);
  auto write = [&](bool background, bool close, Bytes& bytes) {
    McapWriterOptions o = options_for(GetParam(), 64 << 10);
    o.background = background;
    McapWriter w(std::make_unique<MemorySink>(bytes), o);
    for (const TopicSpec& t : kTopics) w.add_channel(0, t.topic, t.encoding);
    for (std::size_t i = 0; i < run.size(); ++i) {
      const Written& m = run[i];
      w.write(m.channel, m.sequence, m.log_time, m.publish_time, m.data.data(), m.data.size());
      if (i == run.size() / 4) w.write_metadata("between", {{"i", std::to_string(i)}});
      if (i == run.size() / 3) w.write_attachment({1, 2, "a.txt", "text/plain", Bytes(300, 7)});
      if (i == run.size() / 2) w.add_channel(w.add_schema("late", "jsonschema", "{}"), "/late", "json");
    }
    if (close) w.close();
  };
  Bytes inline_bytes, background_bytes, unclosed_inline, unclosed_background;
  write(false, true, inline_bytes);
  write(true, true, background_bytes);
  EXPECT_EQ(background_bytes, inline_bytes);
  EXPECT_GT(open_reader(background_bytes)->chunk_indexes().size(), 5u);
  write(false, false, unclosed_inline);
  write(true, false, unclosed_background);
  EXPECT_EQ(unclosed_background, unclosed_inline);
  EXPECT_GT(unclosed_background.size(), inline_bytes.size() / 2);
}

TEST_P(Compressions, AFlippedBitInAChunkIsACrcMismatch) {
  const std::vector<Written> run = make_run(0.1, 8, 1500);
  const Bytes bytes = write_file(run, options_for(GetParam(), 16 << 10));
  const auto chunks = chunk_ends_and_counts(bytes);
  const ChunkIndex c = open_reader(bytes)->chunk_indexes()[2];
  Bytes b = bytes;
  b[c.chunk_start_offset + c.chunk_length - 100] ^= 0x04;  // inside the records, near the end
  auto r = open_reader(b);  // the summary is intact
  try {
    read_all(*r);
    ADD_FAILURE() << "the damaged chunk was read";
  } catch (const McapError& e) {
    EXPECT_EQ(e.offset(), c.chunk_start_offset) << e.what();
    if (GetParam() == Compression::None) {
      EXPECT_NE(std::string(e.what()).find("CRC mismatch"), std::string::npos) << e.what();
    }
  }
  try {
    r->verify_data_crc();
    ADD_FAILURE() << "the data section's CRC held";
  } catch (const McapError& e) {
    EXPECT_NE(std::string(e.what()).find("data section CRC mismatch"), std::string::npos) << e.what();
  }
  // the stream stops at the chunk, with the two chunks before it
  const Streamed s = stream_all(b.data(), b.size());
  EXPECT_TRUE(s.status.stopped);
  EXPECT_EQ(s.status.error_offset, c.chunk_start_offset) << s.status.error;
  EXPECT_EQ(s.messages.size(), chunks[0].second + chunks[1].second);
  // a flipped bit in a Message Index record (no chunk CRC covers it): the data section's CRC
  Bytes mb = bytes;
  mb[c.chunk_start_offset + c.chunk_length + 9 + 2 + 4 + 3] ^= 0x20;  // the first entry's log_time
  auto mr = open_reader(mb);
  EXPECT_EQ(read_all(*mr).size(), run.size());  // the reader goes by the chunks themselves
  EXPECT_THROW(mr->verify_data_crc(), McapError);
  const Streamed ms = stream_all(mb.data(), mb.size());
  EXPECT_EQ(ms.messages.size(), run.size());
  EXPECT_TRUE(ms.status.stopped);
  EXPECT_FALSE(ms.status.data_end);
  EXPECT_NE(ms.status.error.find("data section CRC mismatch"), std::string::npos) << ms.status.error;
  EXPECT_TRUE(stream_all(mb.data(), mb.size(), false).status.complete);
  // a flipped bit in the summary: open() says so
  Bytes sb = bytes;
  sb[r->footer().summary_start + 20] ^= 0x01;
  try {
    open_reader(sb);
    ADD_FAILURE() << "the damaged summary opened";
  } catch (const McapError& e) {
    EXPECT_NE(std::string(e.what()).find("summary CRC mismatch"), std::string::npos) << e.what();
  }
}

TEST_P(Compressions, AChunkRunningPastTheEndIsAnError) {
  const std::vector<Written> run = make_run(0.1, 9, 1500);
  const Bytes bytes = write_file(run, options_for(GetParam(), 16 << 10));
  const auto chunks = chunk_ends_and_counts(bytes);
  const auto r0 = open_reader(bytes);
  const ChunkIndex c = r0->chunk_indexes()[1];
  // the Chunk record's own length past the end of the file
  Bytes b = bytes;
  put64(b, c.chunk_start_offset + 1, b.size());
  auto r = open_reader(b);
  EXPECT_THROW(read_all(*r), McapError);
  const Streamed s = stream_all(b.data(), b.size());
  EXPECT_TRUE(s.status.stopped);
  EXPECT_EQ(s.status.error_offset, c.chunk_start_offset);
  EXPECT_NE(s.status.error.find("claims"), std::string::npos) << s.status.error;
  EXPECT_EQ(s.messages.size(), chunks[0].second);
  // the Chunk Index's chunk_length past the end (the summary CRC made right again)
  try {
    open_reader(with_chunk_index_field(bytes, c.chunk_start_offset, 24, 1ull << 40));
    ADD_FAILURE() << "a chunk index past the end opened";
  } catch (const McapError& e) {
    EXPECT_NE(std::string(e.what()).find("not inside the data section"), std::string::npos) << e.what();
  }
  // a Chunk Index whose message_start_time lies (later than its first message): an error, not a wrong order
  auto r1 = open_reader(with_chunk_index_field(bytes, c.chunk_start_offset, 0, c.message_start_time + 1));
  try {
    read_all(*r1);
    ADD_FAILURE() << "a chunk index with a wrong start time was read";
  } catch (const McapError& e) {
    EXPECT_NE(std::string(e.what()).find("outside the Chunk Index's"), std::string::npos) << e.what();
  }
}

TEST(McapBadInput, LyingLengthsAndAnUnknownCompressionAreErrors) {
  const std::vector<Written> run = make_run(0.05, 10, 700);
  const Bytes plain = write_file(run, options_for(Compression::None, 8 << 10));
  const Bytes zstd = write_file(run, options_for(Compression::Zstd, 8 << 10));
  const auto chunks = chunk_ends_and_counts(plain);
  // the Header's length past the end
  {
    Bytes b = plain;
    put64(b, 9, 1ull << 62);
    EXPECT_THROW(open_reader(b), McapError);
    const Streamed s = stream_all(b.data(), b.size());
    EXPECT_TRUE(s.status.stopped);
    EXPECT_EQ(s.status.error_offset, 8u);
    EXPECT_TRUE(s.messages.empty());
  }
  // a Message record's length inside an uncompressed chunk: too long, too short (the chunk's CRC cleared)
  const ChunkIndex c = open_reader(plain)->chunk_indexes()[1];
  const std::size_t records = static_cast<std::size_t>(c.chunk_start_offset) + 9 + 40;
  ASSERT_EQ(plain.at(records), 0x05);
  for (const std::uint64_t lie : {std::uint64_t{1} << 40, std::uint64_t{3}}) {
    Bytes b = plain;
    put32(b, static_cast<std::size_t>(c.chunk_start_offset) + 9 + 24, 0);
    put64(b, records + 1, lie);
    auto r = open_reader(b);
    try {
      read_all(*r);
      ADD_FAILURE() << "a message of length " << lie << " was read";
    } catch (const McapError& e) {
      EXPECT_EQ(e.offset(), c.chunk_start_offset);
      EXPECT_NE(std::string(e.what()).find("Message record"), std::string::npos) << e.what();
    }
    const Streamed s = stream_all(b.data(), b.size());
    EXPECT_TRUE(s.status.stopped);
    EXPECT_EQ(s.status.error_offset, c.chunk_start_offset) << s.status.error;
    EXPECT_LE(s.status.offset, c.chunk_start_offset);  // the damaged chunk is not accepted
    EXPECT_EQ(s.messages.size(), chunks[0].second) << s.status.error;
  }
  // an unknown compression ("zstd" made "lz4!")
  {
    Bytes b = zstd;
    const ChunkIndex z = open_reader(zstd)->chunk_indexes()[0];
    const std::size_t name = static_cast<std::size_t>(z.chunk_start_offset) + 9 + 28;
    ASSERT_EQ(str_at(b, name), "zstd");
    std::memcpy(&b[name + 4], "lz4!", 4);
    auto r = open_reader(b);
    try {
      read_all(*r);
      ADD_FAILURE() << "an lz4! chunk was read";
    } catch (const McapError& e) {
      EXPECT_NE(std::string(e.what()).find("unknown compression \"lz4!\""), std::string::npos) << e.what();
    }
    const Streamed s = stream_all(b.data(), b.size());
    EXPECT_TRUE(s.status.stopped);
    EXPECT_TRUE(s.messages.empty());
    EXPECT_NE(s.status.error.find("unknown compression"), std::string::npos);
  }
  // a zstd chunk whose uncompressed_size lies (far larger, then smaller): no allocation of it, an error
  for (const std::uint64_t lie : {std::uint64_t{1} << 50, std::uint64_t{10}}) {
    Bytes b = zstd;
    const ChunkIndex z = open_reader(zstd)->chunk_indexes()[0];
    put64(b, static_cast<std::size_t>(z.chunk_start_offset) + 9 + 16, lie);
    auto r = open_reader(b);
    EXPECT_THROW(read_all(*r), McapError);
    EXPECT_TRUE(stream_all(b.data(), b.size()).status.stopped);
  }
}

TEST(McapBadInput, GarbageAndMutationsAreErrorsNeverCrashes) {
  std::mt19937 rng(1234);
  // random bytes, with and without the magic in front
  for (int i = 0; i < 200; ++i) {
    Bytes b(std::uniform_int_distribution<std::size_t>(0, 3000)(rng));
    for (auto& x : b) x = static_cast<std::uint8_t>(rng());
    if (i % 2) b.insert(b.begin(), kMagic, kMagic + 8);
    EXPECT_THROW(open_reader(b), McapError);
    const Streamed s = stream_all(b.data(), b.size());
    EXPECT_TRUE(s.status.stopped);
    EXPECT_TRUE(s.messages.empty());
  }
  // a valid file with a few bytes changed anywhere, many times over
  const std::vector<Written> run = make_run(0.03, 12, 300);
  for (const Compression c : {Compression::None, Compression::Zstd}) {
    const Bytes good = write_file(run, options_for(c, 4 << 10));
    int opened = 0;
    for (int i = 0; i < 1500; ++i) {
      Bytes b = good;
      const int changes = 1 + i % 4;
      for (int k = 0; k < changes; ++k) {
        b[std::uniform_int_distribution<std::size_t>(0, b.size() - 1)(rng)] = static_cast<std::uint8_t>(rng());
      }
      // half the time with the summary's CRC cleared, so the summary's parser sees the damage
      if (i % 2) put32(b, b.size() - 12, 0);
      bool ok = false;
      read_or_mcap_error(b, &ok);
      opened += ok;
      const Streamed s = stream_all(b.data(), b.size());
      EXPECT_LE(s.messages.size(), run.size());
      // without CRCs the mutations reach the parsers themselves
      const Streamed u = stream_all(b.data(), b.size(), false);
      EXPECT_TRUE(u.status.complete || u.status.stopped);
    }
    EXPECT_GT(opened, 0);
  }
}

// ------------------------------------------------------------ the file sink

TEST(McapFileSink, NothingAtThePathUntilCloseThenTheWholeFile) {
  const TestDir tmp_dir;
  const fs::path& dir = tmp_dir.path;
  const fs::path path = dir / "run.mcap";
  const fs::path tmp = dir / "run.mcap.tmp";
  const std::vector<Written> run = make_run(0.05, 13, 1000);
  auto write_some = [&](McapWriter& w) {
    const std::uint16_t ch = w.add_channel(0, "/lidar/packets", "ouster.lidar_packet.legacy");
    for (const Written& m : run) {
      if (m.channel == 1) w.write(ch, m.sequence, m.log_time, m.publish_time, m.data.data(), m.data.size());
    }
  };
  // destroyed without close(): only the .tmp, which streams up to its last whole chunk
  {
    McapWriter w(std::make_unique<FileSink>(path.string()), options_for(Compression::Zstd, 8 << 10));
    write_some(w);
    EXPECT_FALSE(fs::exists(path));
    EXPECT_TRUE(fs::exists(tmp));
  }
  EXPECT_FALSE(fs::exists(path));
  ASSERT_TRUE(fs::exists(tmp));
  {
    McapStreamReader s(std::make_unique<FileSource>(tmp.string()));
    Message m;
    std::size_t n = 0;
    while (s.next(m)) ++n;
    EXPECT_TRUE(s.status().stopped);
    EXPECT_GT(n, 0u);
  }
  // an old file at the path stays until close() replaces it whole
  save(path, Bytes{'o', 'l', 'd'});
  {
    McapWriter w(std::make_unique<FileSink>(path.string()), options_for(Compression::Zstd, 8 << 10));
    write_some(w);
    EXPECT_EQ(fs::file_size(path), 3u);
    w.close();
    EXPECT_FALSE(fs::exists(tmp));
    EXPECT_GT(fs::file_size(path), 1000u);
  }
  McapReader r(std::make_unique<FileSource>(path.string()));
  r.open();
  std::size_t lidar = 0;
  for (const Written& m : run) lidar += m.channel == 1;
  EXPECT_EQ(r.statistics()->message_count, lidar);
  EXPECT_EQ(read_all(r).size(), lidar);
  EXPECT_NO_THROW(r.verify_data_crc());
}

// a sink that fails once it has taken `limit` bytes (a full disk)
class FailingSink final : public ByteSink {
 public:
  explicit FailingSink(std::size_t limit) : limit_(limit) {}
  void write(const std::uint8_t*, std::size_t n) override {
    if (taken_ + n > limit_) throw std::runtime_error("disk full");
    taken_ += n;
  }
  void close() override { ADD_FAILURE() << "a failed file was closed"; }

 private:
  std::size_t limit_, taken_ = 0;
};

TEST(McapWriter, AFailedSinkLeavesTheFileUnfinishedForGood) {
  McapWriter w(std::make_unique<FailingSink>(20'000), options_for(Compression::None, 4096));
  const std::uint16_t ch = w.add_channel(0, "/raw", "raw");
  const Bytes data(1000, 1);
  std::uint32_t i = 0;
  EXPECT_THROW(
      for (;; ++i) w.write(ch, i, i, i, data.data(), data.size()), std::runtime_error);
  EXPECT_GT(i, 10u);
  EXPECT_THROW(w.write(ch, 0, 0, 0, data.data(), data.size()), std::logic_error);
  EXPECT_THROW(w.close(), std::logic_error);
  EXPECT_THROW(w.close(), std::logic_error);
}

TEST(McapFileSink, AnUnwritablePathIsAnErrorNamingIt) {
  try {
    FileSink s("/nonexistent-folder/run.mcap");
    ADD_FAILURE() << "opened";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-folder/run.mcap.tmp"), std::string::npos) << e.what();
  }
  EXPECT_THROW(FileSource("/nonexistent-folder/run.mcap"), std::runtime_error);
}

}  // namespace
