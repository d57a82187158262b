// validate_mcap.mjs FILE: reads an MCAP file with the official TypeScript
// reader (@mcap/core): McapIndexedReader through the summary and the chunk
// indexes, McapStreamReader record by record, both with validateCrcs; checks
// that they agree with each other and with the Statistics record, and that
// the data section's CRC (which neither reader checks) is right; prints one
// JSON line: {"messages","chunks","first_log_time","last_log_time",
// "schemas" (names, sorted),"topics" (messages per topic, sorted)}.
// Exit 0: valid; 1: invalid (the reason on stderr); 2: usage; 3: the
// modules are missing (NODE_PATH: <build>/mcap-validator/node_modules,
// installed by ./paddock test).
import { readFileSync } from "node:fs";
import { createRequire } from "node:module";

// the modules, found through NODE_PATH (require honours it, import does not)
const require = createRequire(import.meta.url);
function load(name) {
  try {
    return require(name);
  } catch (error) {
    console.error(
      `validate_mcap: cannot load ${name} (NODE_PATH=${process.env.NODE_PATH ?? ""}): ` +
        `run ./paddock test, which installs it into <build>/mcap-validator (${error.message.split("\n")[0]})`,
    );
    process.exit(3);
  }
}
const { McapIndexedReader, McapStreamReader } = load("@mcap/core");
const { decompress } = load("fzstd");

const file = process.argv[2];
if (!file || process.argv.length !== 3) {
  console.error("usage: node validate_mcap.mjs FILE");
  process.exit(2);
}
function fail(message) {
  console.error(`validate_mcap: ${file}: ${message}`);
  process.exit(1);
}

// zstd chunks through fzstd, held to the chunk's uncompressed_size
const decompressHandlers = {
  zstd: (buffer, size) => {
    const out = decompress(buffer);
    if (BigInt(out.length) !== size) {
      throw new Error(`a zstd chunk decompresses to ${out.length} bytes, its uncompressed_size says ${size}`);
    }
    return out;
  },
};

// the standard CRC-32 (written here: the data section's CRC is checked by neither reader)
const crcTable = new Uint32Array(256);
for (let i = 0; i < 256; i++) {
  let c = i;
  for (let k = 0; k < 8; k++) c = c & 1 ? (c >>> 1) ^ 0xedb88320 : c >>> 1;
  crcTable[i] = c >>> 0;
}
function crc32(bytes) {
  let c = 0xffffffff;
  for (let i = 0; i < bytes.length; i++) c = crcTable[(c ^ bytes[i]) & 0xff] ^ (c >>> 8);
  return (c ^ 0xffffffff) >>> 0;
}

// per-topic counts and the first and last log times of a message sequence
function tally() {
  return { topics: new Map(), count: 0n, min: undefined, max: undefined };
}
function add(t, topic, logTime) {
  t.topics.set(topic, (t.topics.get(topic) ?? 0n) + 1n);
  t.count += 1n;
  if (t.min === undefined || logTime < t.min) t.min = logTime;
  if (t.max === undefined || logTime > t.max) t.max = logTime;
}
function sameCounts(a, b) {
  if (a.size !== b.size) return false;
  for (const [k, v] of a) if (b.get(k) !== v) return false;
  return true;
}
function show(map) {
  return JSON.stringify(Object.fromEntries([...map].map(([k, v]) => [k, v.toString()])));
}

async function main() {
  const bytes = new Uint8Array(readFileSync(file));

  // the indexed reader: footer, summary (its CRC), chunk indexes, message indexes, chunk CRCs
  const readable = {
    size: async () => BigInt(bytes.length),
    read: async (offset, size) => bytes.subarray(Number(offset), Number(offset + size)),
  };
  const indexed = await McapIndexedReader.Initialize({ readable, decompressHandlers });
  if (indexed.footer.summaryCrc === 0) fail("the Footer has no summary_crc");
  if (indexed.dataSectionCrc === undefined) fail("Data End has no data_section_crc");
  const dataCrc = crc32(bytes.subarray(0, Number(indexed.dataEndOffset)));
  if (dataCrc !== indexed.dataSectionCrc) {
    fail(`data section CRC mismatch: computed ${dataCrc}, Data End says ${indexed.dataSectionCrc}`);
  }
  const byIndex = tally();
  let previous;
  for await (const m of indexed.readMessages({ validateCrcs: true })) {
    const channel = indexed.channelsById.get(m.channelId);
    if (!channel) fail(`indexed reader: a message on channel ${m.channelId}, which the summary lacks`);
    if (previous !== undefined && m.logTime < previous) fail("indexed reader: messages out of log-time order");
    previous = m.logTime;
    add(byIndex, channel.topic, m.logTime);
  }

  // the streaming reader: every record from the start, chunk CRCs, the Footer and Magic at the end
  const stream = new McapStreamReader({ decompressHandlers, validateCrcs: true, includeChunks: true });
  stream.append(bytes);
  const channels = new Map();
  const byStream = tally();
  let streamChunks = 0;
  for (let record; (record = stream.nextRecord()); ) {
    if (record.type === "Channel") channels.set(record.id, record);
    if (record.type === "Chunk") streamChunks += 1;
    if (record.type === "Message") {
      const channel = channels.get(record.channelId);
      if (!channel) fail(`stream reader: a message on channel ${record.channelId} before its Channel record`);
      add(byStream, channel.topic, record.logTime);
    }
  }
  if (!stream.done()) fail("stream reader: the file does not end with the Footer and the Magic");

  // the two readers agree, and agree with the Statistics record
  if (!sameCounts(byIndex.topics, byStream.topics)) {
    fail(`the readers disagree: indexed ${show(byIndex.topics)}, stream ${show(byStream.topics)}`);
  }
  if (streamChunks !== indexed.chunkIndexes.length) {
    fail(`${streamChunks} Chunk records, ${indexed.chunkIndexes.length} Chunk Index records`);
  }
  const stats = indexed.statistics;
  if (!stats) fail("no Statistics record");
  if (stats.messageCount !== byIndex.count) fail(`Statistics: ${stats.messageCount} messages, read ${byIndex.count}`);
  if (stats.chunkCount !== indexed.chunkIndexes.length) fail(`Statistics: ${stats.chunkCount} chunks`);
  if (byIndex.count > 0n && (stats.messageStartTime !== byIndex.min || stats.messageEndTime !== byIndex.max)) {
    fail(`Statistics: times [${stats.messageStartTime}, ${stats.messageEndTime}], read [${byIndex.min}, ${byIndex.max}]`);
  }
  const perTopic = new Map();
  for (const [id, count] of stats.channelMessageCounts) {
    const channel = indexed.channelsById.get(id);
    if (!channel) fail(`Statistics: counts for channel ${id}, which the summary lacks`);
    perTopic.set(channel.topic, (perTopic.get(channel.topic) ?? 0n) + count);
  }
  if (!sameCounts(perTopic, byIndex.topics)) {
    fail(`Statistics: channel counts ${show(perTopic)}, read ${show(byIndex.topics)}`);
  }

  // the line the test compares
  const schemas = [...indexed.schemasById.values()].map((s) => s.name).sort();
  const topics = [...byIndex.topics.keys()].sort();
  const time = (t) => (t === undefined ? "null" : t.toString());
  console.log(
    `{"messages":${byIndex.count},"chunks":${indexed.chunkIndexes.length},` +
      `"first_log_time":${time(byIndex.min)},"last_log_time":${time(byIndex.max)},` +
      `"schemas":[${schemas.map((s) => JSON.stringify(s)).join(",")}],` +
      `"topics":{${topics.map((t) => `${JSON.stringify(t)}:${byIndex.topics.get(t)}`).join(",")}}}`,
  );
}

main().catch((error) => fail(error.message));
