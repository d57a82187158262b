// an MCAP log (autonomy/log/mcap.h): read through its summary
// (McapReader: every message, metadata, attachments, the data CRC; a
// McapError for anything damaged) and record by record from its start
// (McapStreamReader: never throws, stops at the damage and says where)
#include <memory>

#include "autonomy/log/mcap.h"
#include "fuzz/fuzz_target.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace log = paddock::log;
  try {
    log::McapReader r(std::make_unique<log::MemorySource>(data, size));
    r.open();
    log::McapReader::Messages m = r.messages();
    log::Message msg;
    while (m.next(msg)) {
    }
    (void)r.read_metadata();
    (void)r.read_attachments();
    r.verify_data_crc();
  } catch (const log::McapError&) {
  }
  log::McapStreamReader s(std::make_unique<log::MemorySource>(data, size));
  log::Message msg;
  std::uint64_t n = 0;
  while (s.next(msg)) ++n;
  if (s.status().messages != n) __builtin_trap();
  if (!s.status().complete && !s.status().stopped && size > 0 && s.status().offset > size) __builtin_trap();
  return 0;
}
