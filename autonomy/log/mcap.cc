#include "autonomy/log/mcap.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <future>
#include <set>
#include <utility>

namespace paddock::log {

namespace {

// the fixed sizes the specification gives ("Records", "Footer", "Data End", "Message")
constexpr std::size_t kRecordPrefix = 9;                    // opcode, uint64 content length
constexpr std::size_t kFooterContent = 8 + 8 + 4;           // summary_start, summary_offset_start, summary_crc
constexpr std::size_t kFooterAndMagic = kRecordPrefix + kFooterContent + sizeof kMagic;
constexpr std::size_t kDataEndRecord = kRecordPrefix + 4;   // data_section_crc
constexpr std::size_t kMessageFields = 2 + 4 + 8 + 8;       // channel_id, sequence, log_time, publish_time
constexpr std::size_t kHeaderMinimum = kRecordPrefix + 4 + 4;  // two empty strings
constexpr std::uint64_t kNoChunk = std::numeric_limits<std::uint64_t>::max();

// "Records": the names used in messages
const char* op_name(std::uint8_t op) {
  static const char* const names[] = {"opcode 0x00",   "Header",     "Footer",         "Schema",
                                      "Channel",       "Message",    "Chunk",          "Message Index",
                                      "Chunk Index",   "Attachment", "Attachment Index", "Statistics",
                                      "Metadata",      "Metadata Index", "Summary Offset", "Data End"};
  if (op < sizeof names / sizeof names[0]) return names[op];
  return op >= 0x80 ? "private record" : "unknown record";
}

// bytes, a CRC and an opcode in hex, for the messages
std::string hex_bytes(const std::uint8_t* p, std::size_t n) {
  static const char digits[] = "0123456789ABCDEF";
  std::string s;
  for (std::size_t i = 0; i < n; ++i) {
    if (i) s += ' ';
    s += digits[p[i] >> 4];
    s += digits[p[i] & 0x0F];
  }
  return s;
}

std::string hex32(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08X", static_cast<unsigned>(v));
  return buf;
}

std::string opcode_hex(std::uint8_t op) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02X", static_cast<unsigned>(op));
  return buf;
}

// "Fixed-width types": little-endian, byte by byte (any host)
std::uint16_t load16(const std::uint8_t* p) {
  return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}
std::uint32_t load32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}
std::uint64_t load64(const std::uint8_t* p) {
  return static_cast<std::uint64_t>(load32(p)) | static_cast<std::uint64_t>(load32(p + 4)) << 32;
}

// ------------------------------------------------------------ the reading cursor

// reads fields from a record's bytes, every length checked against the
// bytes that remain. Positions are file offsets (base + pos), or, inside a
// chunk's records (chunk != kNoChunk), offsets into the uncompressed records
// reported with the chunk's file offset.
class In {
 public:
  In(const std::uint8_t* p, std::size_t n, std::uint64_t base, const char* record, std::uint64_t chunk = kNoChunk)
      : p_(p), n_(n), base_(base), record_(record), chunk_(chunk) {}

  std::size_t remaining() const { return n_ - pos_; }
  std::uint64_t position() const { return base_ + pos_; }
  std::size_t pos() const { return pos_; }
  const std::uint8_t* here() const { return p_ + pos_; }

  [[noreturn]] void fail(const std::string& what) const { fail_at(pos_, what); }
  [[noreturn]] void fail_at(std::size_t pos, const std::string& what) const {
    const std::string where = std::string(record_) + " record";
    if (chunk_ == kNoChunk) throw McapError(base_ + pos, where + ": " + what);
    throw McapError(chunk_, "in the chunk's records at byte " + std::to_string(base_ + pos) + ": " + where + ": " + what);
  }
  void need(std::uint64_t k, const char* field) const {
    if (k > remaining()) {
      fail(std::string(field) + " needs " + std::to_string(k) + " bytes, only " + std::to_string(remaining()) +
           " remain in the record");
    }
  }
  const std::uint8_t* take(std::uint64_t k, const char* field) {
    need(k, field);
    const std::uint8_t* at = p_ + pos_;
    pos_ += static_cast<std::size_t>(k);
    return at;
  }
  std::uint8_t u8(const char* field) { return *take(1, field); }
  std::uint16_t u16(const char* field) { return load16(take(2, field)); }
  std::uint32_t u32(const char* field) { return load32(take(4, field)); }
  std::uint64_t u64(const char* field) { return load64(take(8, field)); }
  // "String": uint32 byte length, then the bytes
  std::string str(const char* field) {
    const std::uint32_t n = u32(field);
    const std::uint8_t* s = take(n, field);
    return std::string(reinterpret_cast<const char*>(s), n);
  }
  // uint32 length-prefixed Bytes
  std::vector<std::uint8_t> bytes32(const char* field) {
    const std::uint32_t n = u32(field);
    const std::uint8_t* s = take(n, field);
    return std::vector<std::uint8_t>(s, s + n);
  }
  // "Map<string, string>": uint32 byte length, then key and value strings
  KeyValues string_map(const char* field) {
    const std::uint32_t n = u32(field);
    In sub(take(n, field), n, base_ + pos_ - n, record_, chunk_);
    KeyValues m;
    while (sub.remaining() > 0) {
      std::string k = sub.str(field);
      m[std::move(k)] = sub.str(field);
    }
    return m;
  }
  // "Map<uint16, uint64>": uint32 byte length, then 10-byte entries
  std::map<std::uint16_t, std::uint64_t> id_map(const char* field) {
    const std::uint32_t n = u32(field);
    if (n % 10 != 0) fail(std::string(field) + ": a byte length of " + std::to_string(n) + ", not a multiple of 10");
    const std::uint8_t* s = take(n, field);
    std::map<std::uint16_t, std::uint64_t> m;
    for (std::uint32_t i = 0; i < n; i += 10) m[load16(s + i)] = load64(s + i + 2);
    return m;
  }

 private:
  const std::uint8_t* p_;
  std::size_t n_;
  std::size_t pos_ = 0;
  std::uint64_t base_;
  const char* record_;
  std::uint64_t chunk_;
};

// ------------------------------------------------------------ record parsers (readers)

// "Header (op=0x01)"
Header parse_header(In& in) {
  Header h;
  h.profile = in.str("profile");
  h.library = in.str("library");
  return h;
}

// "Schema (op=0x03)"
Schema parse_schema(In& in) {
  Schema s;
  s.id = in.u16("id");
  s.name = in.str("name");
  s.encoding = in.str("encoding");
  s.data = in.bytes32("data");
  return s;
}

// "Channel (op=0x04)"
Channel parse_channel(In& in) {
  Channel c;
  c.id = in.u16("id");
  c.schema_id = in.u16("schema_id");
  c.topic = in.str("topic");
  c.message_encoding = in.str("message_encoding");
  c.metadata = in.string_map("metadata");
  return c;
}

// "Message (op=0x05)": the fields; data is the rest of the record
Message parse_message(In& in) {
  Message m;
  m.channel_id = in.u16("channel_id");
  m.sequence = in.u32("sequence");
  m.log_time = in.u64("log_time");
  m.publish_time = in.u64("publish_time");
  m.size = in.remaining();
  m.data = in.take(m.size, "data");
  return m;
}

// "Chunk Index (op=0x08)"
ChunkIndex parse_chunk_index(In& in) {
  ChunkIndex c;
  c.message_start_time = in.u64("message_start_time");
  c.message_end_time = in.u64("message_end_time");
  c.chunk_start_offset = in.u64("chunk_start_offset");
  c.chunk_length = in.u64("chunk_length");
  c.message_index_offsets = in.id_map("message_index_offsets");
  c.message_index_length = in.u64("message_index_length");
  c.compression = in.str("compression");
  c.compressed_size = in.u64("compressed_size");
  c.uncompressed_size = in.u64("uncompressed_size");
  return c;
}

// "Attachment (op=0x09)", its crc (of the preceding fields) checked when asked and not 0
Attachment parse_attachment(In& in, bool validate_crc) {
  const std::uint8_t* start = in.here();
  Attachment a;
  a.log_time = in.u64("log_time");
  a.create_time = in.u64("create_time");
  a.name = in.str("name");
  a.media_type = in.str("media_type");
  const std::uint64_t n = in.u64("data");
  const std::uint8_t* d = in.take(n, "data");
  a.data.assign(d, d + n);
  const std::size_t covered = static_cast<std::size_t>(in.here() - start);
  const std::uint32_t crc = in.u32("crc");
  if (validate_crc && crc != 0) {
    const std::uint32_t computed = crc32(start, covered);
    if (computed != crc) in.fail("crc mismatch: computed " + hex32(computed) + ", the record says " + hex32(crc));
  }
  return a;
}

// "Attachment Index (op=0x0A)"
AttachmentIndex parse_attachment_index(In& in) {
  AttachmentIndex a;
  a.offset = in.u64("offset");
  a.length = in.u64("length");
  a.log_time = in.u64("log_time");
  a.create_time = in.u64("create_time");
  a.data_size = in.u64("data_size");
  a.name = in.str("name");
  a.media_type = in.str("media_type");
  return a;
}

// "Statistics (op=0x0B)"
Statistics parse_statistics(In& in) {
  Statistics s;
  s.message_count = in.u64("message_count");
  s.schema_count = in.u16("schema_count");
  s.channel_count = in.u32("channel_count");
  s.attachment_count = in.u32("attachment_count");
  s.metadata_count = in.u32("metadata_count");
  s.chunk_count = in.u32("chunk_count");
  s.message_start_time = in.u64("message_start_time");
  s.message_end_time = in.u64("message_end_time");
  s.channel_message_counts = in.id_map("channel_message_counts");
  return s;
}

// "Metadata (op=0x0C)"
Metadata parse_metadata(In& in) {
  Metadata m;
  m.name = in.str("name");
  m.metadata = in.string_map("metadata");
  return m;
}

// "Metadata Index (op=0x0D)"
MetadataIndex parse_metadata_index(In& in) {
  MetadataIndex m;
  m.offset = in.u64("offset");
  m.length = in.u64("length");
  m.name = in.str("name");
  return m;
}

// ------------------------------------------------------------ zstd

// "Chunk": compression "zstd" — the records decompressed to exactly
// `declared` bytes. The buffer grows with what the frames actually give
// (never to a size a lying uncompressed_size asks for up front); one byte
// beyond `declared` shows a chunk that is longer than it says.
std::vector<std::uint8_t> unzstd(ZSTD_DCtx* dctx, const std::uint8_t* src, std::size_t n, std::uint64_t declared,
                                 std::uint64_t at) {
  if (declared >= std::numeric_limits<std::size_t>::max() / 2) {
    throw McapError(at, "Chunk record: uncompressed_size " + std::to_string(declared) + " is not a size");
  }
  const std::size_t cap = static_cast<std::size_t>(declared) + 1;
  std::vector<std::uint8_t> out(std::min(cap, std::max<std::size_t>(4 * n, 1u << 16)));
  ZSTD_DCtx_reset(dctx, ZSTD_reset_session_only);
  ZSTD_inBuffer in{src, n, 0};
  std::size_t produced = 0;
  // each pass must consume input or produce output; a pass that does neither is damage
  for (;;) {
    if (produced == out.size()) {
      if (out.size() == cap) break;
      out.resize(std::min(cap, out.size() * 2));
    }
    ZSTD_outBuffer ob{out.data(), out.size(), produced};
    const std::size_t in_before = in.pos;
    const std::size_t r = ZSTD_decompressStream(dctx, &ob, &in);
    if (ZSTD_isError(r)) throw McapError(at, std::string("Chunk record: zstd: ") + ZSTD_getErrorName(r));
    const bool progress = ob.pos != produced || in.pos != in_before;
    produced = ob.pos;
    if (r == 0 && in.pos == in.size) break;  // the last frame is complete
    if (in.pos == in.size && produced < out.size()) {
      throw McapError(at, "Chunk record: the zstd data ends inside a frame (cut short)");
    }
    if (!progress) throw McapError(at, "Chunk record: zstd makes no progress on the chunk's data");
  }
  if (produced != declared) {
    throw McapError(at, "Chunk record: the zstd data decompresses to " +
                            (produced == cap ? "more than " + std::to_string(declared)
                                             : std::to_string(produced)) +
                            " bytes; uncompressed_size says " + std::to_string(declared));
  }
  out.resize(produced);
  return out;
}

// a chunk's records, decompressed and checked: compression, sizes, CRC
// ("Chunk (op=0x06)"); `chunk_at` is the Chunk record's file offset
struct ChunkRecords {
  std::vector<std::uint8_t> storage;  // the decompressed records (zstd)
  const std::uint8_t* data = nullptr;  // the records (into storage or the caller's record)
  std::size_t size = 0;
  std::uint64_t message_start_time = 0, message_end_time = 0;
};
ChunkRecords open_chunk(In& in, ZSTD_DCtx* dctx, bool validate_crc, std::uint64_t chunk_at) {
  ChunkRecords c;
  c.message_start_time = in.u64("message_start_time");
  c.message_end_time = in.u64("message_end_time");
  const std::uint64_t uncompressed_size = in.u64("uncompressed_size");
  const std::uint32_t uncompressed_crc = in.u32("uncompressed_crc");
  const std::uint64_t compression_at = in.position();
  const std::string compression = in.str("compression");
  const std::uint64_t records_size = in.u64("records");
  const std::uint8_t* records = in.take(records_size, "records");
  // the registry's compressions this reader knows
  if (compression.empty()) {
    if (uncompressed_size != records_size) {
      throw McapError(chunk_at, "Chunk record: uncompressed, yet uncompressed_size " + std::to_string(uncompressed_size) +
                                    " differs from the records' " + std::to_string(records_size) + " bytes");
    }
    c.data = records;
    c.size = static_cast<std::size_t>(records_size);
  } else if (compression == "zstd") {
    c.storage = unzstd(dctx, records, static_cast<std::size_t>(records_size), uncompressed_size, chunk_at);
    c.data = c.storage.data();
    c.size = c.storage.size();
  } else {
    throw McapError(compression_at, "Chunk record: unknown compression \"" + compression +
                                        "\" (this reader knows \"\" and \"zstd\")");
  }
  // "Chunk": uncompressed_crc, 0 meaning none
  if (validate_crc && uncompressed_crc != 0) {
    const std::uint32_t computed = crc32(c.data, c.size);
    if (computed != uncompressed_crc) {
      throw McapError(chunk_at, "Chunk record: CRC mismatch: the uncompressed records' CRC-32 is " + hex32(computed) +
                                    ", uncompressed_crc says " + hex32(uncompressed_crc));
    }
  }
  return c;
}

// one record of a chunk's records: opcode, its content (length checked)
struct RawRecord {
  std::uint8_t op = 0;
  std::size_t at = 0;  // the record's start in the records
  const std::uint8_t* content = nullptr;
  std::size_t size = 0;
};
RawRecord next_record(In& in) {
  RawRecord r;
  r.at = in.pos();
  in.need(kRecordPrefix, "the record's opcode and length");
  r.op = in.u8("opcode");
  const std::uint64_t len = in.u64("length");
  if (len > in.remaining()) {
    in.fail_at(r.at, std::string(op_name(r.op)) + " record claims " + std::to_string(len) + " bytes, only " +
                         std::to_string(in.remaining()) + " remain");
  }
  r.size = static_cast<std::size_t>(len);
  r.content = in.take(len, "content");
  return r;
}

// ------------------------------------------------------------ the writing buffer

// "Serialization": fields appended little-endian
struct Out {
  std::vector<std::uint8_t>& b;
  void u8(std::uint8_t v) { b.push_back(v); }
  void u16(std::uint16_t v) {
    b.push_back(static_cast<std::uint8_t>(v));
    b.push_back(static_cast<std::uint8_t>(v >> 8));
  }
  void u32(std::uint32_t v) {
    for (int i = 0; i < 4; ++i) b.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  void u64(std::uint64_t v) {
    for (int i = 0; i < 8; ++i) b.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  void raw(const void* p, std::size_t n) {
    const auto* s = static_cast<const std::uint8_t*>(p);
    b.insert(b.end(), s, s + n);
  }
  static std::uint32_t length32(std::size_t n, const char* what) {
    if (n > std::numeric_limits<std::uint32_t>::max()) {
      throw std::invalid_argument(std::string("mcap: ") + what + " is longer than 4 GiB");
    }
    return static_cast<std::uint32_t>(n);
  }
  void str(const std::string& s) {
    u32(length32(s.size(), "a string"));
    raw(s.data(), s.size());
  }
  void bytes32(const std::vector<std::uint8_t>& d) {
    u32(length32(d.size(), "a byte field"));
    raw(d.data(), d.size());
  }
  // "Map<string, string>": the byte length first
  void string_map(const KeyValues& m) {
    std::size_t n = 0;
    for (const auto& [k, v] : m) n += 8 + k.size() + v.size();
    u32(length32(n, "a map"));
    for (const auto& [k, v] : m) {
      str(k);
      str(v);
    }
  }
  void id_map(const std::map<std::uint16_t, std::uint64_t>& m) {
    u32(length32(10 * m.size(), "a map"));
    for (const auto& [k, v] : m) {
      u16(k);
      u64(v);
    }
  }
  // "Records": opcode, uint64 content length (patched by end)
  std::size_t begin(Op op) {
    const std::size_t at = b.size();
    u8(static_cast<std::uint8_t>(op));
    u64(0);
    return at;
  }
  void end(std::size_t at) {
    const std::uint64_t len = b.size() - at - kRecordPrefix;
    for (int i = 0; i < 8; ++i) b[at + 1 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(len >> (8 * i));
  }
};

}  // namespace

// ------------------------------------------------------------ errors, names, CRC

McapError::McapError(std::uint64_t offset, const std::string& what)
    : std::runtime_error("mcap: byte " + std::to_string(offset) + ": " + what), offset_(offset) {}

const char* compression_name(Compression c) { return c == Compression::Zstd ? "zstd" : ""; }

// zlib's: the same CRC (its slicing, about 4 GB/s on an EPYC; our own
// slicing-by-8 tables did 2 GB/s, and carry-less multiplication 13.5 GB/s
// in 60 lines of intrinsics, measured 2026-11-29: zlib's costs a percent
// of a logged run and 3 % of a replay, not worth keeping our own), in
// pieces zlib's length type holds
std::uint32_t crc32(const void* data, std::size_t n, std::uint32_t crc) {
  const auto* p = static_cast<const Bytef*>(data);
  uLong c = crc;
  while (n > 0) {
    const std::size_t piece = std::min<std::size_t>(n, 1u << 30);
    c = ::crc32(c, p, static_cast<uInt>(piece));
    p += piece;
    n -= piece;
  }
  return static_cast<std::uint32_t>(c);
}

// ------------------------------------------------------------ sinks and sources

// memory: appended to the caller's vector
void MemorySink::write(const std::uint8_t* data, std::size_t n) {
  if (n) out_.insert(out_.end(), data, data + n);
}

// FILE ACCESS: the .tmp opened for writing
FileSink::FileSink(std::string path) : path_(std::move(path)) {
  file_ = std::fopen(temp_path().c_str(), "wb");
  if (!file_) throw std::runtime_error(temp_path() + ": cannot write: " + std::strerror(errno));
}

// FILE ACCESS: unclosed, the .tmp stays as it is and path is not touched
FileSink::~FileSink() {
  if (file_) std::fclose(file_);
}

// FILE ACCESS: bytes appended to the .tmp
void FileSink::write(const std::uint8_t* data, std::size_t n) {
  if (!file_) throw std::logic_error(path_ + ": write after close");
  if (n && std::fwrite(data, 1, n, file_) != n) {
    throw std::runtime_error(temp_path() + ": write failed: " + std::strerror(errno));
  }
}

// FILE ACCESS: the .tmp flushed, closed and renamed over path
void FileSink::close() {
  if (!file_) return;
  std::FILE* f = file_;
  file_ = nullptr;
  const bool flushed = std::fflush(f) == 0;
  const int flush_errno = errno;
  if (std::fclose(f) != 0 || !flushed) {
    throw std::runtime_error(temp_path() + ": write failed: " + std::strerror(flushed ? errno : flush_errno));
  }
  if (std::rename(temp_path().c_str(), path_.c_str()) != 0) {
    throw std::runtime_error(path_ + ": cannot rename " + temp_path() + " into place: " + std::strerror(errno));
  }
}

// memory: owned, or a view of the caller's bytes
MemorySource::MemorySource(std::vector<std::uint8_t> bytes)
    : owned_(std::move(bytes)), data_(owned_.data()), n_(owned_.size()) {}

MemorySource::MemorySource(const std::uint8_t* data, std::size_t n) : data_(data), n_(n) {}

void MemorySource::read(std::uint64_t offset, std::uint8_t* out, std::size_t n) {
  if (offset > n_ || n > n_ - offset) {
    throw McapError(offset, "needs " + std::to_string(n) + " bytes, the file ends at byte " + std::to_string(n_));
  }
  if (n) std::memcpy(out, data_ + offset, n);
}

// FILE ACCESS: the file opened for reading, its size taken now
FileSource::FileSource(const std::string& path) : path_(path) {
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) throw std::runtime_error(path + ": cannot open: " + std::strerror(errno));
  struct stat st {};
  if (::fstat(fd_, &st) != 0) {
    const int e = errno;
    ::close(fd_);
    throw std::runtime_error(path + ": cannot stat: " + std::strerror(e));
  }
  size_ = static_cast<std::uint64_t>(st.st_size);
}

FileSource::~FileSource() {
  if (fd_ >= 0) ::close(fd_);
}

// FILE ACCESS: pread until the range is read
void FileSource::read(std::uint64_t offset, std::uint8_t* out, std::size_t n) {
  if (offset > size_ || n > size_ - offset) {
    throw McapError(offset, "needs " + std::to_string(n) + " bytes, the file ends at byte " + std::to_string(size_));
  }
  std::size_t done = 0;
  while (done < n) {
    const ssize_t r = ::pread(fd_, out + done, n - done, static_cast<off_t>(offset + done));
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) {
      throw std::runtime_error(path_ + ": read failed at byte " + std::to_string(offset + done) + ": " +
                               (r < 0 ? std::strerror(errno) : "the file got shorter"));
    }
    done += static_cast<std::size_t>(r);
  }
}

// ------------------------------------------------------------ writer

struct McapWriter::Impl {
  std::unique_ptr<ByteSink> sink;
  McapWriterOptions opt;
  std::uint64_t offset = 0;  // bytes handed to the sink
  std::uint32_t crc = 0;     // the running CRC of the section being written (data, then summary)
  bool closed = false;
  bool broken = false;       // a sink write failed: the file is unfinished for good

  std::vector<Schema> schemas;    // id i + 1
  std::vector<Channel> channels;  // id i + 1
  std::vector<std::uint64_t> channel_counts;
  std::vector<std::uint8_t> record;  // one top-level record being built

  // the open chunk: its records, times and per-channel (log_time, offset) index
  std::vector<std::uint8_t> chunk;
  std::uint64_t chunk_start = 0, chunk_end = 0;
  bool chunk_has_messages = false;
  std::vector<std::vector<std::uint64_t>> chunk_index;  // per channel id - 1: log_time, offset, ...
  std::vector<std::uint16_t> chunk_channels;            // channels with messages in the open chunk
  ZSTD_CCtx* cctx = nullptr;

  // a full chunk, sealed: its records, its Message Index records (built:
  // they hold no file offset) and times; compressed by `compressing` (on
  // its own thread with options.background), written by write_sealed()
  struct Sealed {
    std::vector<std::uint8_t> records, compressed, indexes;
    std::vector<std::pair<std::uint16_t, std::size_t>> index_at;  // channel, its record's start in indexes
    std::uint64_t start = 0, end = 0;
    std::uint32_t crc = 0;          // of the records
    std::size_t payload_size = 0;   // the compressed bytes (the records' size when uncompressed)
  };
  Sealed sealed;
  std::future<void> compressing;  // valid: `sealed` is waiting to be written

  mutable Statistics stats;
  std::vector<ChunkIndex> chunk_indexes;
  std::vector<MetadataIndex> metadata_indexes;
  std::vector<AttachmentIndex> attachment_indexes;

  ~Impl() {
    if (compressing.valid()) compressing.wait();  // the thread uses cctx
    ZSTD_freeCCtx(cctx);
  }

  // compresses `sealed` (on the compressing thread, or deferred to write_sealed())
  void compress_sealed();
  // the open chunk into `sealed` (the one before it written first), its
  // compression started; the chunk starts over empty (on the storage the
  // last sealed one had)
  void seal_chunk();
  // the sealed chunk, once compressed, into the file: the Chunk record and
  // its Message Index records (nothing when none is sealed)
  void write_sealed();

  // bytes to the sink, counted and into the running CRC; a failed write breaks the writer
  void emit(const std::uint8_t* p, std::size_t n) {
    try {
      sink->write(p, n);
    } catch (...) {
      broken = true;
      throw;
    }
    crc = crc32(p, n, crc);
    offset += n;
  }
  void emit_record() {
    emit(record.data(), record.size());
    record.clear();
  }
  void check_open() const {
    if (broken) throw std::logic_error("mcap: an earlier write to the sink failed: the file stays unfinished");
    if (closed) throw std::logic_error("mcap: the writer is closed");
  }
};

McapWriter::McapWriter(std::unique_ptr<ByteSink> sink, McapWriterOptions options) : impl_(std::make_unique<Impl>()) {
  Impl& w = *impl_;
  if (!sink) throw std::invalid_argument("mcap: no sink");
  w.sink = std::move(sink);
  w.opt = std::move(options);
  if (w.opt.compression == Compression::Zstd) {
    w.cctx = ZSTD_createCCtx();
    if (!w.cctx) throw std::runtime_error("mcap: ZSTD_createCCtx failed");
  }
  w.chunk.reserve(static_cast<std::size_t>(std::min<std::uint64_t>(w.opt.chunk_size, 64u << 20)) + 4096);
  // "Magic", then "Header (op=0x01)"
  w.emit(kMagic, sizeof kMagic);
  Out o{w.record};
  const std::size_t at = o.begin(Op::Header);
  o.str(w.opt.profile);
  o.str(w.opt.library);
  o.end(at);
  w.emit_record();
}

McapWriter::~McapWriter() {
  // unclosed: a chunk still being compressed is written as it would have
  // been without the thread (the .tmp keeps every whole chunk), best effort
  Impl& w = *impl_;
  if (w.closed || w.broken) return;
  try {
    w.write_sealed();
  } catch (...) {
  }
}

std::uint16_t McapWriter::add_schema(const std::string& name, const std::string& encoding, const std::string& data) {
  return add_schema(name, encoding, std::vector<std::uint8_t>(data.begin(), data.end()));
}

std::uint16_t McapWriter::add_schema(const std::string& name, const std::string& encoding,
                                     const std::vector<std::uint8_t>& data) {
  Impl& w = *impl_;
  w.check_open();
  w.write_sealed();  // a chunk still being compressed comes first
  if (w.schemas.size() >= 0xFFFFu) throw std::invalid_argument("mcap: more than 65535 schemas");
  Schema s;
  s.id = static_cast<std::uint16_t>(w.schemas.size() + 1);
  s.name = name;
  s.encoding = encoding;
  s.data = data;
  // "Schema (op=0x03)" in the data section, before any channel uses it
  Out o{w.record};
  const std::size_t at = o.begin(Op::Schema);
  o.u16(s.id);
  o.str(s.name);
  o.str(s.encoding);
  o.bytes32(s.data);
  o.end(at);
  w.emit_record();
  w.schemas.push_back(std::move(s));
  return w.schemas.back().id;
}

std::uint16_t McapWriter::add_channel(std::uint16_t schema_id, const std::string& topic,
                                      const std::string& message_encoding, const KeyValues& metadata) {
  Impl& w = *impl_;
  w.check_open();
  w.write_sealed();  // a chunk still being compressed comes first
  if (schema_id > w.schemas.size()) throw std::invalid_argument("mcap: unknown schema id " + std::to_string(schema_id));
  if (w.channels.size() >= 0xFFFFu) throw std::invalid_argument("mcap: more than 65535 channels");
  Channel c;
  c.id = static_cast<std::uint16_t>(w.channels.size() + 1);
  c.schema_id = schema_id;
  c.topic = topic;
  c.message_encoding = message_encoding;
  c.metadata = metadata;
  // "Channel (op=0x04)" in the data section, before any message on it
  Out o{w.record};
  const std::size_t at = o.begin(Op::Channel);
  o.u16(c.id);
  o.u16(c.schema_id);
  o.str(c.topic);
  o.str(c.message_encoding);
  o.string_map(c.metadata);
  o.end(at);
  w.emit_record();
  w.channels.push_back(std::move(c));
  w.channel_counts.push_back(0);
  w.chunk_index.emplace_back();
  return w.channels.back().id;
}

void McapWriter::write(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time_ns,
                       std::uint64_t publish_time_ns, const std::string& data) {
  write(channel_id, sequence, log_time_ns, publish_time_ns, reinterpret_cast<const std::uint8_t*>(data.data()),
        data.size());
}

void McapWriter::write(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time_ns,
                       std::uint64_t publish_time_ns, const std::uint8_t* data, std::size_t n) {
  Impl& w = *impl_;
  w.check_open();
  if (channel_id == 0 || channel_id > w.channels.size()) {
    throw std::invalid_argument("mcap: unknown channel id " + std::to_string(channel_id));
  }
  // "Message (op=0x05)" appended to the open chunk's records
  const std::uint64_t offset_in_chunk = w.chunk.size();
  std::uint8_t head[kRecordPrefix + kMessageFields];
  {
    // the fixed fields, little-endian
    std::uint8_t* p = head;
    auto put = [&p](std::uint64_t v, int bytes) {
      for (int i = 0; i < bytes; ++i) *p++ = static_cast<std::uint8_t>(v >> (8 * i));
    };
    put(static_cast<std::uint8_t>(Op::Message), 1);
    put(kMessageFields + n, 8);
    put(channel_id, 2);
    put(sequence, 4);
    put(log_time_ns, 8);
    put(publish_time_ns, 8);
  }
  w.chunk.insert(w.chunk.end(), head, head + sizeof head);
  if (n) w.chunk.insert(w.chunk.end(), data, data + n);
  // the chunk's "Message Index" entry and times
  auto& index = w.chunk_index[channel_id - 1u];
  if (index.empty()) w.chunk_channels.push_back(channel_id);
  index.push_back(log_time_ns);
  index.push_back(offset_in_chunk);
  if (!w.chunk_has_messages) {
    w.chunk_start = w.chunk_end = log_time_ns;
    w.chunk_has_messages = true;
  } else {
    w.chunk_start = std::min(w.chunk_start, log_time_ns);
    w.chunk_end = std::max(w.chunk_end, log_time_ns);
  }
  // the file's "Statistics"
  Statistics& s = w.stats;
  if (s.message_count == 0) {
    s.message_start_time = s.message_end_time = log_time_ns;
  } else {
    s.message_start_time = std::min(s.message_start_time, log_time_ns);
    s.message_end_time = std::max(s.message_end_time, log_time_ns);
  }
  ++s.message_count;
  ++w.channel_counts[channel_id - 1u];
  // full: compressed beside the next one (in the file before anything after it)
  if (w.chunk.size() >= w.opt.chunk_size) w.seal_chunk();
}

void McapWriter::flush_chunk() {
  Impl& w = *impl_;
  w.check_open();
  if (!w.chunk.empty()) w.seal_chunk();
  w.write_sealed();
}

// "Chunk (op=0x06)": the records' CRC, then compressed (or not). It
// touches nothing of the writer's but `sealed` and the compression context.
void McapWriter::Impl::compress_sealed() {
  Sealed& s = sealed;
  s.crc = crc32(s.records.data(), s.records.size());
  s.payload_size = s.records.size();
  if (opt.compression == Compression::Zstd) {
    s.compressed.resize(ZSTD_compressBound(s.records.size()));
    const std::size_t r = ZSTD_compressCCtx(cctx, s.compressed.data(), s.compressed.size(), s.records.data(),
                                            s.records.size(), opt.zstd_level);
    if (ZSTD_isError(r)) throw std::runtime_error(std::string("mcap: zstd: ") + ZSTD_getErrorName(r));
    s.payload_size = r;
  }
}

void McapWriter::Impl::seal_chunk() {
  write_sealed();
  Sealed& s = sealed;
  std::swap(s.records, chunk);
  chunk.clear();
  s.start = chunk_has_messages ? chunk_start : 0;
  s.end = chunk_has_messages ? chunk_end : 0;
  // "Message Index (op=0x07)": one per channel in the chunk, by channel id, entries in file order
  s.indexes.clear();
  s.index_at.clear();
  Out o{s.indexes};
  std::sort(chunk_channels.begin(), chunk_channels.end());
  for (const std::uint16_t ch : chunk_channels) {
    auto& index = chunk_index[ch - 1u];
    s.index_at.emplace_back(ch, s.indexes.size());
    const std::size_t at = o.begin(Op::MessageIndex);
    o.u16(ch);
    o.u32(Out::length32(8 * index.size(), "a message index"));
    for (const std::uint64_t v : index) o.u64(v);
    o.end(at);
    index.clear();
  }
  // the next chunk starts empty
  chunk_channels.clear();
  chunk_has_messages = false;
  ++stats.chunk_count;
  compressing = std::async(opt.background ? std::launch::async : std::launch::deferred, &Impl::compress_sealed, this);
}

void McapWriter::Impl::write_sealed() {
  if (!compressing.valid()) return;
  try {
    compressing.get();
  } catch (...) {
    broken = true;  // the chunk's messages cannot be written: the file stays unfinished
    throw;
  }
  const Sealed& s = sealed;
  const std::uint8_t* payload = opt.compression == Compression::Zstd ? s.compressed.data() : s.records.data();
  ChunkIndex ci;
  ci.message_start_time = s.start;
  ci.message_end_time = s.end;
  ci.chunk_start_offset = offset;
  ci.compression = compression_name(opt.compression);
  ci.compressed_size = s.payload_size;
  ci.uncompressed_size = s.records.size();
  Out o{record};
  o.u8(static_cast<std::uint8_t>(Op::Chunk));
  o.u64(8 + 8 + 8 + 4 + 4 + ci.compression.size() + 8 + s.payload_size);
  o.u64(ci.message_start_time);
  o.u64(ci.message_end_time);
  o.u64(ci.uncompressed_size);
  o.u32(s.crc);
  o.str(ci.compression);
  o.u64(s.payload_size);
  emit_record();
  emit(payload, s.payload_size);
  ci.chunk_length = offset - ci.chunk_start_offset;
  // its Message Index records, where they land
  const std::uint64_t index_start = offset;
  for (const auto& [ch, at] : s.index_at) ci.message_index_offsets[ch] = index_start + at;
  emit(s.indexes.data(), s.indexes.size());
  ci.message_index_length = offset - index_start;
  chunk_indexes.push_back(std::move(ci));
}

void McapWriter::write_metadata(const std::string& name, const KeyValues& metadata) {
  Impl& w = *impl_;
  w.check_open();
  w.write_sealed();  // a chunk still being compressed comes first
  // "Metadata (op=0x0C)" in the data section, its index for the summary
  MetadataIndex mi;
  mi.offset = w.offset;
  mi.name = name;
  Out o{w.record};
  const std::size_t at = o.begin(Op::Metadata);
  o.str(name);
  o.string_map(metadata);
  o.end(at);
  w.emit_record();
  mi.length = w.offset - mi.offset;
  w.metadata_indexes.push_back(std::move(mi));
  ++w.stats.metadata_count;
}

void McapWriter::write_attachment(const Attachment& a) {
  Impl& w = *impl_;
  w.check_open();
  w.write_sealed();  // a chunk still being compressed comes first
  // "Attachment (op=0x09)": its crc covers the fields before it
  AttachmentIndex ai;
  ai.offset = w.offset;
  ai.log_time = a.log_time;
  ai.create_time = a.create_time;
  ai.data_size = a.data.size();
  ai.name = a.name;
  ai.media_type = a.media_type;
  Out o{w.record};
  const std::size_t at = o.begin(Op::Attachment);
  o.u64(a.log_time);
  o.u64(a.create_time);
  o.str(a.name);
  o.str(a.media_type);
  o.u64(a.data.size());
  o.raw(a.data.data(), a.data.size());
  o.u32(crc32(w.record.data() + at + kRecordPrefix, w.record.size() - at - kRecordPrefix));
  o.end(at);
  w.emit_record();
  ai.length = w.offset - ai.offset;
  w.attachment_indexes.push_back(std::move(ai));
  ++w.stats.attachment_count;
}

const Statistics& McapWriter::statistics() const {
  const Impl& w = *impl_;
  // the counts the "Statistics" record carries
  w.stats.schema_count = static_cast<std::uint16_t>(w.schemas.size());
  w.stats.channel_count = static_cast<std::uint32_t>(w.channels.size());
  w.stats.channel_message_counts.clear();
  for (std::size_t i = 0; i < w.channels.size(); ++i) {
    if (w.channel_counts[i]) w.stats.channel_message_counts[static_cast<std::uint16_t>(i + 1)] = w.channel_counts[i];
  }
  return w.stats;
}

std::uint64_t McapWriter::bytes_written() const { return impl_->offset; }

void McapWriter::close() {
  Impl& w = *impl_;
  if (w.closed && !w.broken) return;
  flush_chunk();
  w.closed = true;  // from here a failure leaves the file unfinished, never finished twice
  Out o{w.record};
  // "Data End (op=0x0F)": the CRC of every byte before it
  const std::uint32_t data_crc = w.crc;
  {
    const std::size_t at = o.begin(Op::DataEnd);
    o.u32(data_crc);
    o.end(at);
    w.emit_record();
  }
  // "Summary Section": records grouped by opcode, each group's extent kept for its Summary Offset
  const std::uint64_t summary_start = w.offset;
  w.crc = 0;
  struct Group {
    Op op;
    std::uint64_t start, length;
  };
  std::vector<Group> groups;
  auto group = [&](Op op, auto&& write_records) {
    const std::uint64_t start = w.offset;
    write_records();
    if (w.offset > start) groups.push_back({op, start, w.offset - start});
  };
  group(Op::Schema, [&] {
    for (const Schema& s : w.schemas) {
      const std::size_t at = o.begin(Op::Schema);
      o.u16(s.id);
      o.str(s.name);
      o.str(s.encoding);
      o.bytes32(s.data);
      o.end(at);
      w.emit_record();
    }
  });
  group(Op::Channel, [&] {
    for (const Channel& c : w.channels) {
      const std::size_t at = o.begin(Op::Channel);
      o.u16(c.id);
      o.u16(c.schema_id);
      o.str(c.topic);
      o.str(c.message_encoding);
      o.string_map(c.metadata);
      o.end(at);
      w.emit_record();
    }
  });
  // "Statistics (op=0x0B)" after the channels its counts name
  group(Op::Statistics, [&] {
    const Statistics& s = statistics();
    const std::size_t at = o.begin(Op::Statistics);
    o.u64(s.message_count);
    o.u16(s.schema_count);
    o.u32(s.channel_count);
    o.u32(s.attachment_count);
    o.u32(s.metadata_count);
    o.u32(s.chunk_count);
    o.u64(s.message_start_time);
    o.u64(s.message_end_time);
    o.id_map(s.channel_message_counts);
    o.end(at);
    w.emit_record();
  });
  group(Op::ChunkIndex, [&] {
    for (const ChunkIndex& c : w.chunk_indexes) {
      const std::size_t at = o.begin(Op::ChunkIndex);
      o.u64(c.message_start_time);
      o.u64(c.message_end_time);
      o.u64(c.chunk_start_offset);
      o.u64(c.chunk_length);
      o.id_map(c.message_index_offsets);
      o.u64(c.message_index_length);
      o.str(c.compression);
      o.u64(c.compressed_size);
      o.u64(c.uncompressed_size);
      o.end(at);
      w.emit_record();
    }
  });
  group(Op::MetadataIndex, [&] {
    for (const MetadataIndex& m : w.metadata_indexes) {
      const std::size_t at = o.begin(Op::MetadataIndex);
      o.u64(m.offset);
      o.u64(m.length);
      o.str(m.name);
      o.end(at);
      w.emit_record();
    }
  });
  group(Op::AttachmentIndex, [&] {
    for (const AttachmentIndex& a : w.attachment_indexes) {
      const std::size_t at = o.begin(Op::AttachmentIndex);
      o.u64(a.offset);
      o.u64(a.length);
      o.u64(a.log_time);
      o.u64(a.create_time);
      o.u64(a.data_size);
      o.str(a.name);
      o.str(a.media_type);
      o.end(at);
      w.emit_record();
    }
  });
  // "Summary Offset Section": one record per group
  const std::uint64_t summary_offset_start = w.offset;
  for (const Group& g : groups) {
    const std::size_t at = o.begin(Op::SummaryOffset);
    o.u8(static_cast<std::uint8_t>(g.op));
    o.u64(g.start);
    o.u64(g.length);
    o.end(at);
    w.emit_record();
  }
  // "Footer (op=0x02)": summary_crc covers the summary through summary_offset_start
  {
    o.u8(static_cast<std::uint8_t>(Op::Footer));
    o.u64(kFooterContent);
    o.u64(summary_start);
    o.u64(summary_offset_start);
    o.u32(crc32(w.record.data(), w.record.size(), w.crc));
    w.emit_record();
  }
  // the trailing "Magic", then the sink makes the file final
  w.emit(kMagic, sizeof kMagic);
  w.sink->close();
}

// ------------------------------------------------------------ indexed reader

struct McapReader::Impl {
  std::unique_ptr<ByteSource> src;
  bool opened = false;
  Header header;
  Footer footer;
  std::map<std::uint16_t, Schema> schemas;
  std::map<std::uint16_t, Channel> channels;
  std::optional<Statistics> statistics;
  std::vector<ChunkIndex> chunk_indexes;
  std::vector<MetadataIndex> metadata_indexes;
  std::vector<AttachmentIndex> attachment_indexes;
  std::uint64_t header_end = 0, data_end = 0, footer_offset = 0;
  std::uint32_t data_crc = 0;
  ZSTD_DCtx* dctx = nullptr;

  ~Impl() { ZSTD_freeDCtx(dctx); }

  std::vector<std::uint8_t> read(std::uint64_t offset, std::uint64_t n) {
    if (offset > src->size() || n > src->size() - offset) {
      throw McapError(offset, "needs " + std::to_string(n) + " bytes, the file ends at byte " +
                                  std::to_string(src->size()));
    }
    std::vector<std::uint8_t> b(static_cast<std::size_t>(n));
    src->read(offset, b.data(), b.size());
    return b;
  }
  void check_opened() const {
    if (!opened) throw std::logic_error("mcap: McapReader::open() was not called (or failed)");
  }
  // one record read whole at `offset` (opcode and length checked), for the indexes' targets
  std::vector<std::uint8_t> record_at(std::uint64_t offset, std::uint64_t length, Op expected) {
    if (length < kRecordPrefix || offset < header_end || offset > data_end || length > data_end - offset) {
      throw McapError(offset, std::string("the index points to a ") + op_name(static_cast<std::uint8_t>(expected)) +
                                  " record of " + std::to_string(length) + " bytes outside the data section [" +
                                  std::to_string(header_end) + ", " + std::to_string(data_end) + ")");
    }
    std::vector<std::uint8_t> b = read(offset, length);
    if (b[0] != static_cast<std::uint8_t>(expected)) {
      throw McapError(offset, std::string("expected a ") + op_name(static_cast<std::uint8_t>(expected)) +
                                  " record as the index says, found " + op_name(b[0]) + " (" + opcode_hex(b[0]) + ")");
    }
    if (load64(b.data() + 1) != length - kRecordPrefix) {
      throw McapError(offset, std::string(op_name(b[0])) + " record: its length " + std::to_string(load64(b.data() + 1)) +
                                  " disagrees with the index's " + std::to_string(length - kRecordPrefix));
    }
    return b;
  }
};

McapReader::McapReader(std::unique_ptr<ByteSource> source) : impl_(std::make_unique<Impl>()) {
  if (!source) throw std::invalid_argument("mcap: no source");
  impl_->src = std::move(source);
}

McapReader::~McapReader() = default;

void McapReader::open() {
  Impl& r = *impl_;
  r.opened = false;
  const std::uint64_t size = r.src->size();
  // "Magic" at the start
  if (size < sizeof kMagic) {
    throw McapError(0, "the file is " + std::to_string(size) + " bytes, too short for the Magic");
  }
  std::uint8_t magic[sizeof kMagic];
  r.src->read(0, magic, sizeof magic);
  if (std::memcmp(magic, kMagic, sizeof kMagic) != 0) {
    throw McapError(0, "expected the Magic " + hex_bytes(kMagic, sizeof kMagic) + ", found " +
                           hex_bytes(magic, sizeof magic) + " (not an MCAP file)");
  }
  const std::uint64_t minimum = sizeof kMagic + kHeaderMinimum + kFooterAndMagic;
  if (size < minimum) {
    throw McapError(size, "the file ends at byte " + std::to_string(size) + ": an MCAP file has at least " +
                              std::to_string(minimum) + " (Magic, Header, Footer, Magic; cut short?)");
  }
  // "Header (op=0x01)": the first record, ending before the Footer
  {
    std::uint8_t prefix[kRecordPrefix];
    r.src->read(sizeof kMagic, prefix, sizeof prefix);
    if (prefix[0] != static_cast<std::uint8_t>(Op::Header)) {
      throw McapError(sizeof kMagic, "expected the Header record (opcode 0x01), found " + opcode_hex(prefix[0]));
    }
    const std::uint64_t len = load64(prefix + 1);
    const std::uint64_t room = size - sizeof kMagic - kRecordPrefix - kFooterAndMagic;
    if (len > room) {
      throw McapError(sizeof kMagic + 1, "Header record claims " + std::to_string(len) + " bytes, only " +
                                             std::to_string(room) + " lie before the Footer");
    }
    const std::vector<std::uint8_t> content = r.read(sizeof kMagic + kRecordPrefix, len);
    In in(content.data(), content.size(), sizeof kMagic + kRecordPrefix, "Header");
    r.header = parse_header(in);
    r.header_end = sizeof kMagic + kRecordPrefix + len;
  }
  // "Footer (op=0x02)" and the trailing "Magic"
  r.footer_offset = size - kFooterAndMagic;
  std::uint8_t tail[kFooterAndMagic];
  r.src->read(r.footer_offset, tail, sizeof tail);
  if (std::memcmp(tail + kRecordPrefix + kFooterContent, kMagic, sizeof kMagic) != 0) {
    throw McapError(size - sizeof kMagic, "expected the trailing Magic " + hex_bytes(kMagic, sizeof kMagic) +
                                              ", found " + hex_bytes(tail + kRecordPrefix + kFooterContent, sizeof kMagic) +
                                              " (the file is cut short or damaged; McapStreamReader reads what is there)");
  }
  if (tail[0] != static_cast<std::uint8_t>(Op::Footer) || load64(tail + 1) != kFooterContent) {
    throw McapError(r.footer_offset, "expected the Footer record (opcode 0x02, length 20) before the trailing Magic, "
                                     "found opcode " + opcode_hex(tail[0]) + ", length " + std::to_string(load64(tail + 1)));
  }
  r.footer.summary_start = load64(tail + 9);
  r.footer.summary_offset_start = load64(tail + 17);
  r.footer.summary_crc = load32(tail + 25);
  // the summary's place: after Data End, before the Footer
  if (r.footer.summary_start == 0) {
    throw McapError(r.footer_offset + 9, "the Footer's summary_start is 0: the file has no summary section "
                                         "(McapStreamReader reads it record by record)");
  }
  if (r.footer.summary_start < r.header_end + kDataEndRecord || r.footer.summary_start > r.footer_offset) {
    throw McapError(r.footer_offset + 9, "the Footer's summary_start " + std::to_string(r.footer.summary_start) +
                                             " is outside [" + std::to_string(r.header_end + kDataEndRecord) + ", " +
                                             std::to_string(r.footer_offset) + "]");
  }
  if (r.footer.summary_offset_start != 0 &&
      (r.footer.summary_offset_start < r.footer.summary_start || r.footer.summary_offset_start > r.footer_offset)) {
    throw McapError(r.footer_offset + 17, "the Footer's summary_offset_start " +
                                              std::to_string(r.footer.summary_offset_start) + " is outside [" +
                                              std::to_string(r.footer.summary_start) + ", " +
                                              std::to_string(r.footer_offset) + "]");
  }
  // "Data End (op=0x0F)" just before the summary, then the summary itself
  r.data_end = r.footer.summary_start - kDataEndRecord;
  const std::vector<std::uint8_t> tail_section = r.read(r.data_end, r.footer_offset - r.data_end);
  if (tail_section[0] != static_cast<std::uint8_t>(Op::DataEnd) || load64(tail_section.data() + 1) != 4) {
    throw McapError(r.data_end, "expected the Data End record (opcode 0x0F, length 4) just before summary_start, "
                                "found opcode " + opcode_hex(tail_section[0]));
  }
  r.data_crc = load32(tail_section.data() + kRecordPrefix);
  const std::uint8_t* summary = tail_section.data() + kDataEndRecord;
  const std::size_t summary_size = tail_section.size() - kDataEndRecord;
  // "Footer": summary_crc over the summary (and offsets) through summary_offset_start
  if (r.footer.summary_crc != 0) {
    const std::uint32_t computed = crc32(tail, kRecordPrefix + 16, crc32(summary, summary_size));
    if (computed != r.footer.summary_crc) {
      throw McapError(r.footer.summary_start, "summary CRC mismatch: the summary's CRC-32 is " + hex32(computed) +
                                                  ", the Footer says " + hex32(r.footer.summary_crc));
    }
  }
  // "Summary Section" and "Summary Offset Section": the records they allow
  In in(summary, summary_size, r.footer.summary_start, "summary");
  r.schemas.clear();
  r.channels.clear();
  r.statistics.reset();
  r.chunk_indexes.clear();
  r.metadata_indexes.clear();
  r.attachment_indexes.clear();
  while (in.remaining() > 0) {
    const std::uint64_t at = in.position();
    const RawRecord rec = next_record(in);
    In body(rec.content, rec.size, at + kRecordPrefix, op_name(rec.op));
    switch (static_cast<Op>(rec.op)) {
      case Op::Schema: {
        Schema s = parse_schema(body);
        if (s.id != 0) r.schemas[s.id] = std::move(s);  // "id 0 is invalid and should be ignored"
        break;
      }
      case Op::Channel: {
        Channel c = parse_channel(body);
        r.channels[c.id] = std::move(c);
        break;
      }
      case Op::ChunkIndex:
        r.chunk_indexes.push_back(parse_chunk_index(body));
        break;
      case Op::AttachmentIndex:
        r.attachment_indexes.push_back(parse_attachment_index(body));
        break;
      case Op::MetadataIndex:
        r.metadata_indexes.push_back(parse_metadata_index(body));
        break;
      case Op::Statistics:
        if (r.statistics) throw McapError(at, "a second Statistics record (the file holds at most one)");
        r.statistics = parse_statistics(body);
        break;
      case Op::SummaryOffset:
        break;
      case Op::Header:
      case Op::Footer:
      case Op::Message:
      case Op::Chunk:
      case Op::MessageIndex:
      case Op::Attachment:
      case Op::Metadata:
      case Op::DataEnd:
        throw McapError(at, std::string("a ") + op_name(rec.op) + " record in the summary section (not allowed there)");
      default:
        break;  // unknown and private records are skipped
    }
  }
  // the summary's own consistency: schemas of channels, chunks inside the data section
  for (const auto& [id, c] : r.channels) {
    if (c.schema_id != 0 && !r.schemas.count(c.schema_id)) {
      throw McapError(r.footer.summary_start, "Channel " + std::to_string(id) + " (" + c.topic + ") uses schema " +
                                                  std::to_string(c.schema_id) + ", which the summary lacks");
    }
  }
  for (const ChunkIndex& c : r.chunk_indexes) {
    if (c.chunk_start_offset < r.header_end || c.chunk_start_offset > r.data_end ||
        c.chunk_length > r.data_end - c.chunk_start_offset || c.chunk_length < kRecordPrefix) {
      throw McapError(c.chunk_start_offset, "a Chunk Index gives a chunk of " + std::to_string(c.chunk_length) +
                                                " bytes at byte " + std::to_string(c.chunk_start_offset) +
                                                ", not inside the data section [" + std::to_string(r.header_end) +
                                                ", " + std::to_string(r.data_end) + ")");
    }
  }
  std::stable_sort(r.chunk_indexes.begin(), r.chunk_indexes.end(),
                   [](const ChunkIndex& a, const ChunkIndex& b) { return a.chunk_start_offset < b.chunk_start_offset; });
  if (!r.dctx) r.dctx = ZSTD_createDCtx();
  if (!r.dctx) throw std::runtime_error("mcap: ZSTD_createDCtx failed");
  r.opened = true;
}

const Header& McapReader::header() const { return impl_->check_opened(), impl_->header; }
const Footer& McapReader::footer() const { return impl_->check_opened(), impl_->footer; }
const std::map<std::uint16_t, Schema>& McapReader::schemas() const { return impl_->check_opened(), impl_->schemas; }
const std::map<std::uint16_t, Channel>& McapReader::channels() const { return impl_->check_opened(), impl_->channels; }
const std::optional<Statistics>& McapReader::statistics() const { return impl_->check_opened(), impl_->statistics; }
const std::vector<ChunkIndex>& McapReader::chunk_indexes() const {
  return impl_->check_opened(), impl_->chunk_indexes;
}
const std::vector<MetadataIndex>& McapReader::metadata_indexes() const {
  return impl_->check_opened(), impl_->metadata_indexes;
}
const std::vector<AttachmentIndex>& McapReader::attachment_indexes() const {
  return impl_->check_opened(), impl_->attachment_indexes;
}
std::uint64_t McapReader::data_end_offset() const { return impl_->check_opened(), impl_->data_end; }
std::uint32_t McapReader::data_section_crc() const { return impl_->check_opened(), impl_->data_crc; }

void McapReader::verify_data_crc() {
  Impl& r = *impl_;
  r.check_opened();
  if (r.data_crc == 0) return;
  // "Data End": the CRC of every byte before the Data End record, read in blocks
  std::vector<std::uint8_t> block(1u << 20);
  std::uint32_t crc = 0;
  for (std::uint64_t at = 0; at < r.data_end;) {
    const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(block.size(), r.data_end - at));
    r.src->read(at, block.data(), n);
    crc = crc32(block.data(), n, crc);
    at += n;
  }
  if (crc != r.data_crc) {
    throw McapError(r.data_end, "data section CRC mismatch: bytes [0, " + std::to_string(r.data_end) +
                                    ") have CRC-32 " + hex32(crc) + ", Data End says " + hex32(r.data_crc));
  }
}

std::vector<Metadata> McapReader::read_metadata() {
  Impl& r = *impl_;
  r.check_opened();
  std::vector<Metadata> out;
  // "Metadata Index": each record where it says
  for (const MetadataIndex& mi : r.metadata_indexes) {
    const std::vector<std::uint8_t> b = r.record_at(mi.offset, mi.length, Op::Metadata);
    In in(b.data() + kRecordPrefix, b.size() - kRecordPrefix, mi.offset + kRecordPrefix, "Metadata");
    out.push_back(parse_metadata(in));
  }
  return out;
}

std::vector<Attachment> McapReader::read_attachments() {
  Impl& r = *impl_;
  r.check_opened();
  std::vector<Attachment> out;
  // "Attachment Index": each record where it says, its CRC checked
  for (const AttachmentIndex& ai : r.attachment_indexes) {
    const std::vector<std::uint8_t> b = r.record_at(ai.offset, ai.length, Op::Attachment);
    In in(b.data() + kRecordPrefix, b.size() - kRecordPrefix, ai.offset + kRecordPrefix, "Attachment");
    out.push_back(parse_attachment(in, true));
  }
  return out;
}

// ------------------------------------------------------------ messages across chunks

namespace {
// one message of a loaded chunk: its fields and where its data lies
struct Entry {
  std::uint64_t log_time;
  std::uint64_t publish_time;
  std::size_t data;  // offset of the data in the chunk's records
  std::size_t size;
  std::uint32_t sequence;
  std::uint16_t channel_id;
};
// a chunk being read: its records and its messages in the order they are handed out
struct LoadedChunk {
  std::vector<std::uint8_t> record;  // the Chunk record as read
  std::vector<std::uint8_t> storage;  // decompressed records (zstd)
  const std::uint8_t* records = nullptr;
  std::vector<Entry> entries;
  std::size_t next = 0;
  std::size_t rank = 0;  // the chunk's place in file order
};
}  // namespace

struct McapReader::Messages::Impl {
  McapReader::Impl* r = nullptr;
  ReadOptions opt;
  std::vector<bool> wanted;  // by channel id; empty: every channel
  std::vector<std::pair<const ChunkIndex*, std::size_t>> pending;  // chunks to load (with their rank), in load order
  std::size_t next_pending = 0;
  std::vector<std::unique_ptr<LoadedChunk>> heap;  // loaded chunks with messages left
  std::unique_ptr<LoadedChunk> retired;            // the chunk of the message last handed out

  // the heap's order: the next message's log time (then file order), or file order alone
  bool after(const LoadedChunk& a, const LoadedChunk& b) const {
    if (opt.order == Order::LogTime) {
      const std::uint64_t ta = a.entries[a.next].log_time, tb = b.entries[b.next].log_time;
      if (ta != tb) return ta > tb;
    }
    return a.rank > b.rank;
  }
  void push(std::unique_ptr<LoadedChunk> c) {
    heap.push_back(std::move(c));
    std::push_heap(heap.begin(), heap.end(), [this](const auto& a, const auto& b) { return after(*a, *b); });
  }
  std::unique_ptr<LoadedChunk> pop() {
    std::pop_heap(heap.begin(), heap.end(), [this](const auto& a, const auto& b) { return after(*a, *b); });
    std::unique_ptr<LoadedChunk> c = std::move(heap.back());
    heap.pop_back();
    return c;
  }

  // reads, checks and indexes one chunk ("Chunk (op=0x06)"): its messages in the window
  void load(const ChunkIndex& ci, std::size_t rank) {
    auto c = std::make_unique<LoadedChunk>();
    c->rank = rank;
    c->record = r->record_at(ci.chunk_start_offset, ci.chunk_length, Op::Chunk);
    In in(c->record.data() + kRecordPrefix, c->record.size() - kRecordPrefix, ci.chunk_start_offset + kRecordPrefix,
          "Chunk");
    ChunkRecords cr = open_chunk(in, r->dctx, opt.validate_crcs, ci.chunk_start_offset);
    c->storage = std::move(cr.storage);
    c->records = c->storage.empty() ? cr.data : c->storage.data();
    // the records inside: messages kept, schemas and channels already in the summary
    In rin(c->records, cr.size, 0, "Chunk", ci.chunk_start_offset);
    while (rin.remaining() > 0) {
      const RawRecord rec = next_record(rin);
      if (rec.op != static_cast<std::uint8_t>(Op::Message)) continue;
      In body(rec.content, rec.size, rec.at + kRecordPrefix, "Message", ci.chunk_start_offset);
      const Message m = parse_message(body);
      if (!r->channels.count(m.channel_id)) {
        body.fail_at(0, "on channel " + std::to_string(m.channel_id) + ", which the summary does not declare");
      }
      // the merge in log-time order trusts the Chunk Index's times: they must hold
      if (m.log_time < ci.message_start_time || m.log_time > ci.message_end_time) {
        body.fail_at(0, "log_time " + std::to_string(m.log_time) + " outside the Chunk Index's [" +
                            std::to_string(ci.message_start_time) + ", " + std::to_string(ci.message_end_time) + "]");
      }
      if (m.log_time < opt.start || m.log_time >= opt.end) continue;
      if (!wanted.empty() && !wanted[m.channel_id]) continue;
      c->entries.push_back(
          {m.log_time, m.publish_time, static_cast<std::size_t>(m.data - c->records), m.size, m.sequence, m.channel_id});
    }
    if (opt.order == Order::LogTime) {
      std::stable_sort(c->entries.begin(), c->entries.end(),
                       [](const Entry& a, const Entry& b) { return a.log_time < b.log_time; });
    }
    if (!c->entries.empty()) push(std::move(c));
  }

  bool next(Message& out) {
    retired.reset();
    // load every chunk that may hold a message before the heap's next one
    while (next_pending < pending.size()) {
      const ChunkIndex& ci = *pending[next_pending].first;
      if (!heap.empty()) {
        if (opt.order == Order::File) break;
        const LoadedChunk& top = *heap.front();
        if (ci.message_start_time > top.entries[top.next].log_time) break;
      }
      ++next_pending;
      load(ci, pending[next_pending - 1].second);
    }
    if (heap.empty()) return false;
    std::unique_ptr<LoadedChunk> c = pop();
    const Entry& e = c->entries[c->next++];
    out.channel_id = e.channel_id;
    out.sequence = e.sequence;
    out.log_time = e.log_time;
    out.publish_time = e.publish_time;
    out.data = c->records + e.data;
    out.size = e.size;
    if (c->next < c->entries.size()) {
      push(std::move(c));
    } else {
      retired = std::move(c);  // its bytes stay valid until the next call
    }
    return true;
  }
};

McapReader::Messages::Messages(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
McapReader::Messages::~Messages() = default;
McapReader::Messages::Messages(Messages&&) noexcept = default;
McapReader::Messages& McapReader::Messages::operator=(Messages&&) noexcept = default;
bool McapReader::Messages::next(Message& out) { return impl_->next(out); }

McapReader::Messages McapReader::messages(const ReadOptions& options) {
  Impl& r = *impl_;
  r.check_opened();
  auto m = std::make_unique<Messages::Impl>();
  m->r = &r;
  m->opt = options;
  // the channels of the topics asked for
  if (!options.topics.empty()) {
    m->wanted.assign(0x10000, false);
    const std::set<std::string> topics(options.topics.begin(), options.topics.end());
    for (const auto& [id, c] : r.channels) {
      if (topics.count(c.topic)) m->wanted[id] = true;
    }
  }
  // the chunks that may hold messages in [start, end), in the order they are needed
  for (std::size_t i = 0; i < r.chunk_indexes.size(); ++i) {
    const ChunkIndex& c = r.chunk_indexes[i];
    if (options.start >= options.end) break;
    if (c.message_end_time < options.start || c.message_start_time >= options.end) continue;
    m->pending.emplace_back(&c, i);
  }
  if (options.order == Order::LogTime) {
    std::stable_sort(m->pending.begin(), m->pending.end(), [](const auto& a, const auto& b) {
      return a.first->message_start_time < b.first->message_start_time;
    });
  }
  return Messages(std::move(m));
}

// ------------------------------------------------------------ streaming reader

struct McapStreamReader::Impl {
  std::unique_ptr<ByteSource> src;
  bool validate = true;
  StreamStatus st;
  Header header;
  std::map<std::uint16_t, Schema> schemas;
  std::map<std::uint16_t, Channel> channels;
  std::vector<Metadata> metadata;
  ZSTD_DCtx* dctx = nullptr;

  std::uint64_t pos = 0;      // the next record's offset
  std::uint32_t crc = 0;      // CRC of bytes [0, pos) while in the data section
  bool started = false;       // the Magic read
  bool header_seen = false;
  bool done = false;          // complete or stopped
  std::vector<std::uint8_t> record;   // the current record's content
  std::vector<std::uint8_t> storage;  // the current chunk's decompressed records
  std::vector<Message> pending;       // messages of the current record left to hand out
  std::size_t next = 0;
  bool stop_after_pending = false;    // damage inside the current chunk, after the messages before it
  std::uint64_t pending_error_offset = 0;
  std::string pending_error;

  ~Impl() { ZSTD_freeDCtx(dctx); }

  void stop(std::uint64_t offset, const std::string& why) {
    st.stopped = true;
    st.error_offset = offset;
    st.error = why;
    done = true;
  }

  // the records of a chunk or a message: schemas and channels kept, messages queued
  void take_records(const std::uint8_t* data, std::size_t n, std::uint64_t chunk_at) {
    In in(data, n, 0, "Chunk", chunk_at);
    try {
      while (in.remaining() > 0) {
        const RawRecord rec = next_record(in);
        In body(rec.content, rec.size, rec.at + kRecordPrefix, op_name(rec.op), chunk_at);
        take(rec.op, body, chunk_at);
      }
    } catch (const McapError& e) {
      // damage inside a chunk: what came before it is still handed out
      stop_after_pending = true;
      pending_error_offset = e.offset();
      pending_error = e.what();
    }
  }

  // one record's content, top-level (chunk_at == kNoChunk) or inside a chunk
  void take(std::uint8_t op, In& body, std::uint64_t chunk_at) {
    switch (static_cast<Op>(op)) {
      case Op::Schema: {
        Schema s = parse_schema(body);
        if (s.id != 0) schemas[s.id] = std::move(s);
        break;
      }
      case Op::Channel: {
        Channel c = parse_channel(body);
        if (c.schema_id != 0 && !schemas.count(c.schema_id)) {
          body.fail_at(0, "Channel " + std::to_string(c.id) + " uses schema " + std::to_string(c.schema_id) +
                              ", not seen before it");
        }
        channels[c.id] = std::move(c);
        break;
      }
      case Op::Message: {
        const Message m = parse_message(body);
        if (!channels.count(m.channel_id)) {
          body.fail_at(0, "on channel " + std::to_string(m.channel_id) + ", not seen before it");
        }
        pending.push_back(m);
        break;
      }
      case Op::Chunk: {
        if (chunk_at != kNoChunk) body.fail_at(0, "a Chunk inside a chunk");
        const std::uint64_t at = body.position() - kRecordPrefix;
        if (!dctx) dctx = ZSTD_createDCtx();
        if (!dctx) throw std::runtime_error("mcap: ZSTD_createDCtx failed");
        ChunkRecords cr = open_chunk(body, dctx, validate, at);
        storage = std::move(cr.storage);
        take_records(storage.empty() ? cr.data : storage.data(), cr.size, at);
        ++st.chunks;
        break;
      }
      case Op::Metadata:
        metadata.push_back(parse_metadata(body));
        break;
      case Op::Attachment:
        parse_attachment(body, validate);
        break;
      case Op::Header:
        body.fail_at(0, "a second Header record");
      default:
        break;  // indexes, statistics, summary offsets, unknown and private records
    }
  }

  // reads the next top-level record (or the Magic); stops at damage
  void step() {
    const std::uint64_t size = src->size();
    // "Magic" at the start
    if (!started) {
      std::uint8_t magic[sizeof kMagic];
      if (size < sizeof kMagic) return stop(0, "the file is " + std::to_string(size) + " bytes, too short for the Magic");
      src->read(0, magic, sizeof magic);
      if (std::memcmp(magic, kMagic, sizeof kMagic) != 0) {
        return stop(0, "expected the Magic " + hex_bytes(kMagic, sizeof kMagic) + ", found " +
                           hex_bytes(magic, sizeof magic) + " (not an MCAP file)");
      }
      crc = crc32(magic, sizeof magic);
      pos = st.offset = sizeof kMagic;
      started = true;
      return;
    }
    // "Records": opcode and length, the length within the file
    if (pos == size) return stop(pos, "the file ends at byte " + std::to_string(pos) + " before the Footer (cut short)");
    if (size - pos < kRecordPrefix) {
      return stop(pos, "cut short: a record's opcode and length need 9 bytes, " + std::to_string(size - pos) + " remain");
    }
    std::uint8_t prefix[kRecordPrefix];
    src->read(pos, prefix, sizeof prefix);
    const std::uint8_t op = prefix[0];
    const std::uint64_t len = load64(prefix + 1);
    const std::uint64_t room = size - pos - kRecordPrefix;
    if (op == 0) return stop(pos, "opcode 0x00 is no record (garbage)");
    if (!header_seen && op != static_cast<std::uint8_t>(Op::Header)) {
      return stop(pos, "expected the Header record (opcode 0x01) after the Magic, found " + opcode_hex(op));
    }
    if (len > room) {
      return stop(pos, std::string(op_name(op)) + " record (opcode " + opcode_hex(op) + ") claims " +
                           std::to_string(len) + " bytes, only " + std::to_string(room) +
                           " remain (cut short, or a length that lies)");
    }
    record.resize(static_cast<std::size_t>(len));
    src->read(pos + kRecordPrefix, record.data(), record.size());
    In body(record.data(), record.size(), pos + kRecordPrefix, op_name(op));
    try {
      if (op == static_cast<std::uint8_t>(Op::Header)) {
        if (header_seen) body.fail_at(0, "a second Header record");
        header = parse_header(body);
        header_seen = true;
      } else if (op == static_cast<std::uint8_t>(Op::DataEnd)) {
        // "Data End": the CRC of every byte before it, 0 meaning none
        const std::uint32_t expected = body.u32("data_section_crc");
        if (validate && !st.data_end && expected != 0 && expected != crc) {
          body.fail_at(0, "data section CRC mismatch: bytes [0, " + std::to_string(pos) + ") have CRC-32 " +
                              hex32(crc) + ", Data End says " + hex32(expected));
        }
        st.data_end = true;
      } else if (op == static_cast<std::uint8_t>(Op::Footer)) {
        // "Footer", then the trailing "Magic" and nothing after it
        body.need(kFooterContent, "the Footer's fields");
        const std::uint64_t end = pos + kRecordPrefix + len;
        if (size - end < sizeof kMagic) {
          return stop(end, "cut short: the trailing Magic needs 8 bytes, " + std::to_string(size - end) + " remain");
        }
        std::uint8_t magic[sizeof kMagic];
        src->read(end, magic, sizeof magic);
        if (std::memcmp(magic, kMagic, sizeof kMagic) != 0) {
          return stop(end, "expected the trailing Magic after the Footer, found " + hex_bytes(magic, sizeof magic));
        }
        if (size - end > sizeof kMagic) {
          return stop(end + sizeof kMagic, std::to_string(size - end - sizeof kMagic) +
                                               " bytes after the trailing Magic");
        }
        st.complete = true;
        done = true;
      } else {
        take(op, body, kNoChunk);
      }
    } catch (const McapError& e) {
      pending.clear();
      next = 0;
      stop_after_pending = false;
      return stop(e.offset(), e.what());
    }
    // a chunk damaged inside is not accepted (its messages before the damage are handed out)
    if (stop_after_pending) return;
    // the record accepted: counted, into the data section's CRC
    if (!st.data_end) {
      crc = crc32(prefix, sizeof prefix, crc);
      crc = crc32(record.data(), record.size(), crc);
    }
    pos += kRecordPrefix + len;
    st.offset = st.complete ? size : pos;
    ++st.records;
  }

  bool next_message(Message& out) {
    for (;;) {
      if (next < pending.size()) {
        out = pending[next++];
        ++st.messages;
        return true;
      }
      pending.clear();
      next = 0;
      if (stop_after_pending) {
        stop_after_pending = false;
        stop(pending_error_offset, pending_error);
      }
      if (done) return false;
      step();
    }
  }
};

McapStreamReader::McapStreamReader(std::unique_ptr<ByteSource> source, bool validate_crcs)
    : impl_(std::make_unique<Impl>()) {
  if (!source) throw std::invalid_argument("mcap: no source");
  impl_->src = std::move(source);
  impl_->validate = validate_crcs;
}

McapStreamReader::~McapStreamReader() = default;
bool McapStreamReader::next(Message& out) { return impl_->next_message(out); }
const StreamStatus& McapStreamReader::status() const { return impl_->st; }
const Header& McapStreamReader::header() const { return impl_->header; }
const std::map<std::uint16_t, Schema>& McapStreamReader::schemas() const { return impl_->schemas; }
const std::map<std::uint16_t, Channel>& McapStreamReader::channels() const { return impl_->channels; }
const std::vector<Metadata>& McapStreamReader::metadata() const { return impl_->metadata; }

}  // namespace paddock::log
