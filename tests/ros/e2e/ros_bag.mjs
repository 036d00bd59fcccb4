// SPDX-License-Identifier: GPL-2.0-or-later
// session.mcap read back the way ROS tools and Foxglove read it, by the npm packages alone: @mcap/core's
// indexed reader (summary, chunk indexes, message indexes) and its streaming reader (record by record from
// the start, as after a crash), both checking CRCs; zstd chunks through fzstd; every message decoded as CDR
// with the ros2msg schema the file itself carries (@foxglove/rosmsg + @foxglove/rosmsg2-serialization).

import fs from 'node:fs';

/// The npm packages the readers need, loaded through `require` (see ros_e2e_support.mjs's parseArgs).
export function loadBagPackages(require) {
  const fzstd = require('fzstd');
  return {
    mcap: require('@mcap/core'),
    rosmsg: require('@foxglove/rosmsg'),
    cdr: require('@foxglove/rosmsg2-serialization'),
    crc32: require('@foxglove/crc').crc32,
    // The MCAP spec names "zstd" and "lz4"; rfbsim writes zstd.
    decompressHandlers: { zstd: (buffer, size) => fzstd.decompress(buffer, new Uint8Array(Number(size))) },
  };
}

/// A decoder per schema id: data (CDR bytes) -> a plain object. Throws naming the schema when one is not
/// ros2msg or does not parse.
export function schemaDecoders(pkgs, schemasById) {
  const decoders = new Map();
  for (const [id, schema] of schemasById) {
    if (schema.encoding !== 'ros2msg') throw new Error(`schema ${id} (${schema.name}): encoding '${schema.encoding}'`);
    const text = new TextDecoder().decode(schema.data);
    const reader = new pkgs.cdr.MessageReader(pkgs.rosmsg.parse(text, { ros2: true }));
    decoders.set(id, (data) => reader.readMessage(data));
  }
  return decoders;
}

/// Reads `file` with McapIndexedReader: { reader, messages } with messages in log-time order as it yields
/// them ({ channelId, sequence, logTime, publishTime, data }), CRCs checked. Throws what the reader throws.
export async function readIndexed(pkgs, file) {
  const bytes = fs.readFileSync(file);
  const readable = {
    size: async () => BigInt(bytes.length),
    read: async (offset, size) => {
      if (offset + size > BigInt(bytes.length)) throw new Error(`read past the end (${offset}+${size})`);
      return new Uint8Array(bytes.buffer, bytes.byteOffset + Number(offset), Number(size));
    },
  };
  const reader = await pkgs.mcap.McapIndexedReader.Initialize({ readable,
                                                                decompressHandlers: pkgs.decompressHandlers });
  const messages = [];
  for await (const message of reader.readMessages({ validateCrcs: true })) messages.push(message);
  // The reader checks chunk CRCs; the data section's CRC (DataEnd) is ours to check.
  const dataCrcOk = reader.dataSectionCrc === undefined ||
                    pkgs.crc32(bytes.subarray(0, Number(reader.dataEndOffset))) === reader.dataSectionCrc;
  return { reader, messages, dataCrcOk, dataSectionCrc: reader.dataSectionCrc };
}

/// Reads `file` front to back with McapStreamReader (CRCs checked). Returns { header, schemas, channels,
/// chunks: [{ chunk, messages }], messages (file order), statistics, footer, complete (the footer and the
/// closing magic were read), error (what stopped it early, or null) }. A file cut short mid-record (a killed
/// session) ends with complete false and no error: the streaming reader waits for bytes that never come.
export function readStreamed(pkgs, file) {
  const stream = new pkgs.mcap.McapStreamReader({ includeChunks: true, validateCrcs: true,
                                                 decompressHandlers: pkgs.decompressHandlers });
  stream.append(new Uint8Array(fs.readFileSync(file)));
  const out = { header: null, schemas: new Map(), channels: new Map(), chunks: [], messages: [],
                statistics: null, footer: null, complete: false, error: null };
  try {
    for (let record; (record = stream.nextRecord()) !== undefined;) {
      switch (record.type) {
        case 'Header': out.header = record; break;
        case 'Schema': out.schemas.set(record.id, record); break;
        case 'Channel': out.channels.set(record.id, record); break;
        case 'Chunk': out.chunks.push({ chunk: record, messages: [] }); break;
        case 'Statistics': out.statistics = record; break;
        case 'Footer': out.footer = record; break;
        case 'Message':
          out.messages.push(record);
          // Messages outside any chunk would be legal MCAP; rfbsim writes every message in a chunk.
          if (out.chunks.length > 0) out.chunks[out.chunks.length - 1].messages.push(record);
          break;
        default: break;
      }
    }
    out.complete = stream.done();
  } catch (err) {
    out.error = err.message;
  }
  return out;
}

/// Simulated ns at tick `tick` of a 60 Hz world, as a BigInt (rfbsim: tick * 1e9 / tick_hz, integer).
export function tickNs(tick, tickHz = 60) {
  return (BigInt(tick) * 1_000_000_000n) / BigInt(tickHz);
}

/// Yaw (rad) of a quaternion turning about z only.
export function yawOf(q) {
  return 2 * Math.atan2(q.z, q.w);
}
