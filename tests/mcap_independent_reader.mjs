#!/usr/bin/env node
// Reads an MCAP file with Foxglove's own TypeScript library (@mcap/core), an
// implementation independent of ours, and prints what it found as JSON.
//
// usage: node [--single-threaded] mcap_independent_reader.mjs FILE [--stream-only]
//          [--expect-count TOPIC=N]... [--expect-channels N]
// (--single-threaded avoids a rare deadlock of Node 20 at exit, nodejs/node#54918.)
//
// By default the file is read twice: with McapIndexedReader (footer, summary,
// chunk indexes, message indexes; summary CRC, data section CRC and chunk CRCs
// checked) and with McapStreamReader (record by record from the start, chunk
// CRCs checked); both must agree. --stream-only skips the indexed read, for
// files whose writer died before writing the summary. Exit 0 when every
// expectation holds, 1 on a mismatch or read error, 2 on bad usage.
import { open, readFile } from "node:fs/promises";
import { crc32 } from "@foxglove/crc";
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import { FileHandleReadable } from "@mcap/nodejs";
import decompressLZ4 from "@foxglove/wasm-lz4";
import * as zstd from "@foxglove/wasm-zstd";

function usage(msg) {
  console.error(`mcap_independent_reader: ${msg}`);
  console.error(
    "usage: node mcap_independent_reader.mjs FILE [--stream-only] [--expect-u64-first TOPIC=N]... [--expect-count TOPIC=N]... " +
      "[--expect-channels N]",
  );
  process.exit(2);
}

function parseArgs(argv) {
  const opts = { file: undefined, streamOnly: false, counts: new Map(), channels: undefined, firstU64: new Map() };
  for (let i = 0; i < argv.length; i++) {
    const a = argv[i];
    if (a === "--stream-only") opts.streamOnly = true;
    else if (a === "--expect-count") {
      const m = /^(.+)=(\d+)$/.exec(argv[++i] ?? "");
      if (!m) usage(`--expect-count needs TOPIC=N, got '${argv[i]}'`);
      opts.counts.set(m[1], Number(m[2]));
    } else if (a === "--expect-u64-first") {
      // The first message on TOPIC is CDR (little endian) whose first field is this uint64.
      const m = /^(.+)=(\d+)$/.exec(argv[++i] ?? "");
      if (!m) usage(`--expect-u64-first needs TOPIC=N, got '${argv[i]}'`);
      opts.firstU64.set(m[1], BigInt(m[2]));
    } else if (a === "--expect-channels") {
      const n = Number(argv[++i]);
      if (!Number.isInteger(n)) usage(`--expect-channels needs a number, got '${argv[i]}'`);
      opts.channels = n;
    } else if (a.startsWith("--")) usage(`unknown option ${a}`);
    else if (opts.file === undefined) opts.file = a;
    else usage(`unexpected argument ${a}`);
  }
  if (opts.file === undefined) usage("missing FILE");
  return opts;
}

const decompressHandlers = {
  zstd: (buffer, size) => zstd.decompress(buffer, Number(size)),
  lz4: (buffer, size) => decompressLZ4(buffer, Number(size)),
};

function channelInfo(channelsById, schemasById) {
  return [...channelsById.values()]
    .sort((a, b) => a.id - b.id)
    .map((c) => ({
      id: c.id,
      topic: c.topic,
      schema: schemasById.get(c.schemaId)?.name ?? null,
      schemaEncoding: schemasById.get(c.schemaId)?.encoding ?? null,
      messageEncoding: c.messageEncoding,
      metadata: Object.fromEntries(c.metadata),
    }));
}

// Counts messages per topic; checks log times never decrease when `ordered`.
// The earliest message per topic (both readers see the same bytes), for --expect-u64-first.
const FIRST = {};

function tally(channelsById) {
  const t = { counts: {}, total: 0, start: undefined, end: undefined, outOfOrder: 0, last: undefined };
  t.add = (msg, ordered) => {
    const topic = channelsById.get(msg.channelId)?.topic ?? `<unknown channel ${msg.channelId}>`;
    t.counts[topic] = (t.counts[topic] ?? 0) + 1;
    if (!(topic in FIRST) || msg.logTime < FIRST[topic].logTime)
      FIRST[topic] = { logTime: msg.logTime, data: msg.data };
    t.total++;
    if (t.start === undefined || msg.logTime < t.start) t.start = msg.logTime;
    if (t.end === undefined || msg.logTime > t.end) t.end = msg.logTime;
    if (ordered && t.last !== undefined && msg.logTime < t.last) t.outOfOrder++;
    t.last = msg.logTime;
  };
  return t;
}

async function readIndexed(file) {
  const handle = await open(file, "r");
  try {
    const reader = await McapIndexedReader.Initialize({
      readable: new FileHandleReadable(handle),
      decompressHandlers,
    });
    const t = tally(reader.channelsById);
    for await (const msg of reader.readMessages({ validateCrcs: true })) t.add(msg, true);
    // The data section CRC covers every byte before the Data End record.
    const bytes = await readFile(file);
    const computed = crc32(bytes.subarray(0, Number(reader.dataEndOffset)));
    const stats = reader.statistics;
    return {
      header: { profile: reader.header.profile, library: reader.header.library },
      channels: channelInfo(reader.channelsById, reader.schemasById),
      counts: t.counts,
      total: t.total,
      start: t.start?.toString() ?? null,
      end: t.end?.toString() ?? null,
      outOfOrder: t.outOfOrder,
      chunks: reader.chunkIndexes.length,
      compression: [...new Set(reader.chunkIndexes.map((c) => c.compression))],
      dataSectionCrc: { stored: reader.dataSectionCrc ?? 0, computed },
      statistics: stats && {
        messageCount: stats.messageCount.toString(),
        chunkCount: stats.chunkCount,
        start: stats.messageStartTime.toString(),
        end: stats.messageEndTime.toString(),
        channelMessageCounts: Object.fromEntries(
          [...stats.channelMessageCounts].map(([id, n]) => [reader.channelsById.get(id)?.topic ?? id, Number(n)]),
        ),
      },
    };
  } finally {
    await handle.close();
  }
}

async function readStream(file) {
  const reader = new McapStreamReader({ decompressHandlers, validateCrcs: true });
  reader.append(await readFile(file));
  const channelsById = new Map();
  const schemasById = new Map();
  const t = tally(channelsById);
  let header;
  for (let rec; (rec = reader.nextRecord()); ) {
    if (rec.type === "Header") header = { profile: rec.profile, library: rec.library };
    else if (rec.type === "Schema") schemasById.set(rec.id, rec);
    else if (rec.type === "Channel") channelsById.set(rec.id, rec);
    else if (rec.type === "Message") t.add(rec, false);
  }
  return {
    header,
    channels: channelInfo(channelsById, schemasById),
    counts: t.counts,
    total: t.total,
    start: t.start?.toString() ?? null,
    end: t.end?.toString() ?? null,
    complete: reader.done(),
    unparsedBytes: reader.bytesRemaining(),
  };
}

async function main() {
  const opts = parseArgs(process.argv.slice(2));
  await Promise.all([zstd.isLoaded, decompressLZ4.isLoaded]);
  const failures = [];
  const out = { file: opts.file };

  if (!opts.streamOnly) {
    try {
      out.indexed = await readIndexed(opts.file);
    } catch (e) {
      out.indexedError = String(e?.message ?? e);
      failures.push(`indexed read failed: ${out.indexedError}`);
    }
  }
  try {
    out.stream = await readStream(opts.file);
  } catch (e) {
    out.streamError = String(e?.message ?? e);
    failures.push(`stream read failed: ${out.streamError}`);
  }

  const ix = out.indexed;
  if (ix) {
    if (ix.outOfOrder) failures.push(`indexed read returned ${ix.outOfOrder} messages out of log-time order`);
    const crc = ix.dataSectionCrc;
    if (crc.stored !== 0 && crc.stored !== crc.computed)
      failures.push(`data section CRC: stored ${crc.stored}, computed ${crc.computed}`);
    if (ix.statistics) {
      if (ix.statistics.messageCount !== String(ix.total))
        failures.push(`statistics say ${ix.statistics.messageCount} messages, read ${ix.total}`);
      for (const [topic, n] of Object.entries(ix.counts))
        if (ix.statistics.channelMessageCounts[topic] !== n)
          failures.push(`statistics say ${ix.statistics.channelMessageCounts[topic]} on ${topic}, read ${n}`);
      if (ix.statistics.chunkCount !== ix.chunks)
        failures.push(`statistics say ${ix.statistics.chunkCount} chunks, index has ${ix.chunks}`);
    }
    const sorted = (counts) => JSON.stringify(Object.entries(counts).sort());
    if (out.stream && sorted(out.stream.counts) !== sorted(ix.counts))
      failures.push("indexed and stream readers disagree on message counts");
    if (out.stream && !out.stream.complete) failures.push("stream reader did not reach the footer of an indexed file");
  }

  const found = ix ?? out.stream;
  if (found) {
    for (const [topic, n] of opts.counts)
      if ((found.counts[topic] ?? 0) !== n) failures.push(`${topic}: expected ${n} messages, read ${found.counts[topic] ?? 0}`);
    for (const [topic, want] of opts.firstU64) {
      const d = FIRST[topic]?.data;
      if (!d || d.length < 12) {
        failures.push(`${topic}: no message to decode`);
        continue;
      }
      // 4-byte encapsulation header: 0x00 0x01 is plain CDR, little endian.
      if (d[0] !== 0 || d[1] !== 1) failures.push(`${topic}: encapsulation ${d[0]},${d[1]} is not CDR_LE`);
      const got = new DataView(d.buffer, d.byteOffset + 4, 8).getBigUint64(0, true);
      if (got !== want) failures.push(`${topic}: first field decodes to ${got}, expected ${want}`);
    }
    if (opts.channels !== undefined && found.channels.length !== opts.channels)
      failures.push(`expected ${opts.channels} channels, read ${found.channels.length}`);
  }

  out.ok = failures.length === 0;
  out.failures = failures;
  console.log(JSON.stringify(out, null, 2));
  process.exit(out.ok ? 0 : 1);
}

main().catch((e) => {
  console.error(`mcap_independent_reader: ${e?.stack ?? e}`);
  process.exit(1);
});
