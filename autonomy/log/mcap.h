#pragma once
// MCAP, major version 0 (https://mcap.dev/spec): a writer and two readers of
// the container the run logs are kept in. Cited by the specification's
// section names ("File Structure", "Records", "Serialization", "Chunk", ...).
//
// McapWriter writes a chunked, indexed file: Magic, Header; Schema and
// Channel records in the data section as they are added; Message records in
// Chunks (zstd or uncompressed, with uncompressed_crc), each followed by its
// Message Index records; Metadata and Attachment records between chunks;
// Data End with the data section's CRC; the summary (Schema, Channel,
// Statistics, Chunk Index, Metadata Index, Attachment Index groups), one
// Summary Offset per group; Footer with the summary CRC; Magic.
//
// McapReader reads a whole file through its summary: messages in log-time
// (or file) order across chunks, within a [start, end) log-time window.
// McapStreamReader reads a file from its start record by record (a file
// without a summary: a recording cut short) and stops at the first damaged
// record, saying where and why.
//
// Bad input is a McapError (the byte offset and what was expected), never a
// crash, a hang or an allocation a lying length asked for: every length is
// checked against the bytes that remain.
//
// The log is the edge of the stack: the writer and readers work on byte
// sinks and sources, and the only file access is FileSink and FileSource.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace paddock::log {

// "Magic": the eight bytes at both ends of a file (0x30: major version '0')
inline constexpr std::uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', 0x30, '\r', '\n'};

// "Records": the opcode of each record type
enum class Op : std::uint8_t {
  Header = 0x01,
  Footer = 0x02,
  Schema = 0x03,
  Channel = 0x04,
  Message = 0x05,
  Chunk = 0x06,
  MessageIndex = 0x07,
  ChunkIndex = 0x08,
  Attachment = 0x09,
  AttachmentIndex = 0x0A,
  Statistics = 0x0B,
  Metadata = 0x0C,
  MetadataIndex = 0x0D,
  SummaryOffset = 0x0E,
  DataEnd = 0x0F,
};

// a chunk's compression ("Chunk": compression; the registry's "zstd", or ""
// for none)
enum class Compression { None, Zstd };
// "" or "zstd"
const char* compression_name(Compression c);

// malformed MCAP input: what() is "mcap: byte OFFSET: what was found, what
// was expected"
class McapError : public std::runtime_error {
 public:
  McapError(std::uint64_t offset, const std::string& what);
  // bytes from the start of the file (of the chunk's records, for a record
  // inside a chunk: the message says which)
  std::uint64_t offset() const { return offset_; }

 private:
  std::uint64_t offset_;
};

// the standard CRC-32 (IEEE 802.3, zlib's crc32: reflected 0xEDB88320, all
// ones in and out); chained: crc32(b, m, crc32(a, n)) is the CRC of a then b
std::uint32_t crc32(const void* data, std::size_t n, std::uint32_t crc = 0);

// ---------------------------------------------------------------- bytes

// where a writer's bytes go, in order
class ByteSink {
 public:
  virtual ~ByteSink() = default;
  virtual void write(const std::uint8_t* data, std::size_t n) = 0;
  // the bytes are complete (a file: moved into place); the last call
  virtual void close() = 0;
};

// appends to a vector the caller owns (and keeps alive while writing)
class MemorySink final : public ByteSink {
 public:
  explicit MemorySink(std::vector<std::uint8_t>& out) : out_(out) {}
  void write(const std::uint8_t* data, std::size_t n) override;
  void close() override { closed_ = true; }
  bool closed() const { return closed_; }

 private:
  std::vector<std::uint8_t>& out_;
  bool closed_ = false;
};

// FILE ACCESS (the log's edge): writes `path + ".tmp"` and renames it to
// `path` on close(), so `path` is either absent (or its old contents) or
// the whole file. Destroyed without close(), it leaves `path` untouched
// and what was written in `path + ".tmp"` (McapStreamReader recovers it).
// Throws std::runtime_error (path, errno's text) when the file cannot be
// opened, written or renamed.
class FileSink final : public ByteSink {
 public:
  explicit FileSink(std::string path);
  ~FileSink() override;
  FileSink(const FileSink&) = delete;
  FileSink& operator=(const FileSink&) = delete;
  void write(const std::uint8_t* data, std::size_t n) override;
  void close() override;
  const std::string& path() const { return path_; }
  std::string temp_path() const { return path_ + ".tmp"; }

 private:
  std::string path_;
  std::FILE* file_ = nullptr;
};

// random access to a file's bytes
class ByteSource {
 public:
  virtual ~ByteSource() = default;
  virtual std::uint64_t size() const = 0;
  // bytes [offset, offset + n) into out; a McapError when they are not all
  // inside the source
  virtual void read(std::uint64_t offset, std::uint8_t* out, std::size_t n) = 0;
};

// bytes in memory: owned (the vector) or viewed (the caller keeps them alive)
class MemorySource final : public ByteSource {
 public:
  explicit MemorySource(std::vector<std::uint8_t> bytes);
  MemorySource(const std::uint8_t* data, std::size_t n);
  std::uint64_t size() const override { return n_; }
  void read(std::uint64_t offset, std::uint8_t* out, std::size_t n) override;

 private:
  std::vector<std::uint8_t> owned_;
  const std::uint8_t* data_ = nullptr;
  std::size_t n_ = 0;
};

// FILE ACCESS (the log's edge): a file read with pread; its size is taken
// when opened. Throws std::runtime_error (path, errno's text) when it cannot
// be opened or read.
class FileSource final : public ByteSource {
 public:
  explicit FileSource(const std::string& path);
  ~FileSource() override;
  FileSource(const FileSource&) = delete;
  FileSource& operator=(const FileSource&) = delete;
  std::uint64_t size() const override { return size_; }
  void read(std::uint64_t offset, std::uint8_t* out, std::size_t n) override;

 private:
  std::string path_;
  int fd_ = -1;
  std::uint64_t size_ = 0;
};

// ---------------------------------------------------------------- records

using KeyValues = std::map<std::string, std::string>;

// "Header (op=0x01)"
struct Header {
  std::string profile;
  std::string library;
};

// "Footer (op=0x02)"
struct Footer {
  std::uint64_t summary_start = 0;         // 0: no summary section
  std::uint64_t summary_offset_start = 0;  // 0: no Summary Offset records
  std::uint32_t summary_crc = 0;           // 0: not available
};

// "Schema (op=0x03)"
struct Schema {
  std::uint16_t id = 0;  // never 0
  std::string name;      // "foxglove.PointCloud"
  std::string encoding;  // "jsonschema", "" for none
  std::vector<std::uint8_t> data;
};

// "Channel (op=0x04)"
struct Channel {
  std::uint16_t id = 0;
  std::uint16_t schema_id = 0;  // 0: no schema
  std::string topic;
  std::string message_encoding;  // "json", or a raw wire format's name
  KeyValues metadata;
};

// "Message (op=0x05)" as a reader hands it out: data points into the
// reader's buffers and stays valid until its next call
struct Message {
  std::uint16_t channel_id = 0;
  std::uint32_t sequence = 0;
  std::uint64_t log_time = 0;      // ns
  std::uint64_t publish_time = 0;  // ns
  const std::uint8_t* data = nullptr;
  std::size_t size = 0;
};

// "Chunk Index (op=0x08)"
struct ChunkIndex {
  std::uint64_t message_start_time = 0;
  std::uint64_t message_end_time = 0;
  std::uint64_t chunk_start_offset = 0;
  std::uint64_t chunk_length = 0;  // the whole Chunk record, opcode and length included
  std::map<std::uint16_t, std::uint64_t> message_index_offsets;  // channel -> its Message Index record
  std::uint64_t message_index_length = 0;
  std::string compression;
  std::uint64_t compressed_size = 0;
  std::uint64_t uncompressed_size = 0;
};

// "Attachment (op=0x09)"
struct Attachment {
  std::uint64_t log_time = 0;
  std::uint64_t create_time = 0;
  std::string name;
  std::string media_type;
  std::vector<std::uint8_t> data;
};

// "Attachment Index (op=0x0A)"
struct AttachmentIndex {
  std::uint64_t offset = 0;
  std::uint64_t length = 0;
  std::uint64_t log_time = 0;
  std::uint64_t create_time = 0;
  std::uint64_t data_size = 0;
  std::string name;
  std::string media_type;
};

// "Statistics (op=0x0B)"
struct Statistics {
  std::uint64_t message_count = 0;
  std::uint16_t schema_count = 0;
  std::uint32_t channel_count = 0;
  std::uint32_t attachment_count = 0;
  std::uint32_t metadata_count = 0;
  std::uint32_t chunk_count = 0;
  std::uint64_t message_start_time = 0;  // 0 when there are no messages
  std::uint64_t message_end_time = 0;
  std::map<std::uint16_t, std::uint64_t> channel_message_counts;  // channels with messages
};

// "Metadata (op=0x0C)"
struct Metadata {
  std::string name;
  KeyValues metadata;
};

// "Metadata Index (op=0x0D)"
struct MetadataIndex {
  std::uint64_t offset = 0;
  std::uint64_t length = 0;
  std::string name;
};

// ---------------------------------------------------------------- writer

struct McapWriterOptions {
  std::string profile;                   // Header.profile ("" : none of the well-known ones)
  std::string library = "paddock";       // Header.library
  Compression compression = Compression::Zstd;
  int zstd_level = 1;                    // libzstd's level (1: fastest of the usual ones)
  std::uint64_t chunk_size = 4u << 20;   // a chunk ends once its uncompressed records reach this
  // a full chunk is compressed (and its CRC taken) on a thread of its own
  // while the next one fills, and written at the next record: the file's
  // bytes are the same either way; false: all on the caller's thread
  bool background = true;
};

// writes one MCAP file into a sink. Not thread-safe (its one compressing
// thread, McapWriterOptions::background, is its own business). Every method but the
// destructor throws: std::invalid_argument (an unknown id, too many schemas
// or channels), std::logic_error (used after close, or after the sink
// failed: the file then stays unfinished), or what the sink throws.
class McapWriter {
 public:
  // writes the Magic and the Header
  McapWriter(std::unique_ptr<ByteSink> sink, McapWriterOptions options = {});
  // without close() the file is left unfinished: the sink is destroyed
  // unclosed (a FileSink leaves only its .tmp) and the open chunk is lost
  // (a full one still being compressed is written first)
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  // a Schema record (ids 1, 2, ...): e.g. ("foxglove.PointCloud",
  // "jsonschema", the JSON schema's text)
  std::uint16_t add_schema(const std::string& name, const std::string& encoding, const std::string& data);
  std::uint16_t add_schema(const std::string& name, const std::string& encoding, const std::vector<std::uint8_t>& data);
  // a Channel record (ids 1, 2, ...) on schema_id (0: no schema);
  // message_encoding "json" or, for a raw wire format, its own name
  std::uint16_t add_channel(std::uint16_t schema_id, const std::string& topic, const std::string& message_encoding,
                            const KeyValues& metadata = {});
  // one Message record into the open chunk; the chunk is written once its
  // records reach chunk_size. Log times need not be in order.
  void write(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time_ns, std::uint64_t publish_time_ns,
             const std::uint8_t* data, std::size_t n);
  void write(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time_ns, std::uint64_t publish_time_ns,
             const std::string& data);
  // a Metadata record in the data section (indexed in the summary)
  void write_metadata(const std::string& name, const KeyValues& metadata);
  // an Attachment record in the data section, with its CRC (indexed in the summary)
  void write_attachment(const Attachment& attachment);
  // writes the open chunk now (nothing when it is empty), and one still
  // being compressed before it
  void flush_chunk();
  // the open chunk, Data End, the summary, the Footer and the Magic; then
  // the sink's close(). A second call does nothing (after a sink failure it
  // throws std::logic_error).
  void close();

  // what the Statistics record says (so far)
  const Statistics& statistics() const;
  // bytes handed to the sink
  std::uint64_t bytes_written() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// ---------------------------------------------------------------- readers

enum class Order {
  LogTime,  // by log_time; equal times in file order
  File,     // as the records lie in the file
};

struct ReadOptions {
  std::uint64_t start = 0;                                         // log_time >= start
  std::uint64_t end = std::numeric_limits<std::uint64_t>::max();  // log_time < end
  Order order = Order::LogTime;
  std::vector<std::string> topics;  // only these topics; empty: all
  bool validate_crcs = true;        // check each chunk's uncompressed_crc
};

// reads a whole file through its summary. open() reads the Magic at both
// ends, the Header, the Footer, Data End and the summary (checking the
// summary CRC); the rest reads chunks on demand. A file without a summary
// (cut short) is a McapError saying to use McapStreamReader.
class McapReader {
 public:
  explicit McapReader(std::unique_ptr<ByteSource> source);
  ~McapReader();
  McapReader(const McapReader&) = delete;
  McapReader& operator=(const McapReader&) = delete;

  // throws McapError
  void open();

  const Header& header() const;
  const Footer& footer() const;
  const std::map<std::uint16_t, Schema>& schemas() const;
  const std::map<std::uint16_t, Channel>& channels() const;
  const std::optional<Statistics>& statistics() const;
  const std::vector<ChunkIndex>& chunk_indexes() const;  // in file order
  const std::vector<MetadataIndex>& metadata_indexes() const;
  const std::vector<AttachmentIndex>& attachment_indexes() const;
  // the Data End record's offset and its data_section_crc (0: none)
  std::uint64_t data_end_offset() const;
  std::uint32_t data_section_crc() const;

  // reads the data section and checks its CRC against Data End's (nothing
  // when that is 0); throws McapError on a mismatch
  void verify_data_crc();
  std::vector<Metadata> read_metadata();
  // each attachment's CRC checked (when not 0)
  std::vector<Attachment> read_attachments();

  // messages of the chunks, as ReadOptions say; holds the chunks that
  // overlap in time, one at a time when they do not
  class Messages {
   public:
    ~Messages();
    Messages(Messages&&) noexcept;
    Messages& operator=(Messages&&) noexcept;
    // the next message, or false at the end; throws McapError
    bool next(Message& out);

   private:
    friend class McapReader;
    struct Impl;
    explicit Messages(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
  };
  // the reader must outlive its Messages; throws McapError (an unknown topic is no error)
  Messages messages(const ReadOptions& options = {});

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// how far McapStreamReader got
struct StreamStatus {
  bool complete = false;     // the Footer and the trailing Magic read: the whole file
  bool stopped = false;      // stopped early: error and error_offset say why and where
  std::uint64_t offset = 0;  // the end of the last whole record accepted
  std::uint64_t error_offset = 0;
  std::string error;
  std::uint64_t records = 0;   // top-level records accepted
  std::uint64_t chunks = 0;    // Chunk records whose messages were handed out
  std::uint64_t messages = 0;  // messages handed out
  bool data_end = false;       // the Data End record read (its CRC checked when asked)
};

// reads a file from its start, record by record, in file order: Schema,
// Channel and Metadata records as they come, the messages of each chunk
// (after its CRC) and outside chunks. At the first damaged record (cut
// short, a CRC mismatch, a length past the end, garbage) it stops: next()
// returns false and status() says where and why; the messages before the
// damage were handed out. Never throws on bad input.
class McapStreamReader {
 public:
  explicit McapStreamReader(std::unique_ptr<ByteSource> source, bool validate_crcs = true);
  ~McapStreamReader();
  McapStreamReader(const McapStreamReader&) = delete;
  McapStreamReader& operator=(const McapStreamReader&) = delete;

  // the next message, or false at the end of the file or the damage
  bool next(Message& out);
  const StreamStatus& status() const;
  const Header& header() const;
  const std::map<std::uint16_t, Schema>& schemas() const;  // seen so far
  const std::map<std::uint16_t, Channel>& channels() const;
  const std::vector<Metadata>& metadata() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace paddock::log
