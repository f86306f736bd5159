#pragma once
// A small MCAP writer (https://mcap.dev/spec, major version 0), ours because
// Debian ships no MCAP library. Pure file I/O: no DDS.
//
// File layout written:
//   Magic, Header,
//   { Schema | Channel }* (outside chunks, written when added),
//   { Chunk(Message*), MessageIndex* }*,
//   DataEnd(data section CRC),
//   summary: Schema*, Channel*, Statistics, ChunkIndex*,
//   summary offsets: SummaryOffset per summary group,
//   Footer(summary start, summary offset start, summary CRC), Magic.
// Every CRC is the spec's CRC32 (the zlib/IEEE one), none is left zero.
//
// Crash safety: flush_chunk() (called automatically when the open chunk
// reaches WriterOptions::chunk_size_bytes) writes the chunk record and its
// Message Index records, then fflush()es. Once it returns, a process crash
// (abort, SIGKILL) leaves a file whose prefix up to and including that chunk
// is complete: every Schema and Channel added so far, and every message of
// every completed chunk. The summary and footer are missing; Reader (scan
// mode) and streaming readers such as @mcap/core's McapStreamReader read such
// a file up to its last complete record. Messages of the open, unflushed
// chunk are lost. Surviving power loss also needs fsync_each_chunk.
#include <cstdint>
#include <cstdio>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace ddswarm::mcap {

/// Chunk compression. Names on disk: "zstd", "lz4" (LZ4 frame format), "".
enum class Compression { none, zstd, lz4 };

/// The on-disk name of a compression ("" for none).
const char* compression_name(Compression c);

/// Writer settings.
struct WriterOptions {
  /// Chunk compression.
  Compression compression = Compression::zstd;
  /// A chunk is closed once its uncompressed records reach this size, bytes, >= 1.
  std::uint64_t chunk_size_bytes = 1u << 20;
  /// zstd level (1..19; 1 is fastest) or lz4 acceleration level (0 = default, 0..12).
  int compression_level = 1;
  /// Header profile: "" (none) or a framework name.
  std::string profile;
  /// Header library string.
  std::string library = "ddswarm";
  /// fsync() after every chunk (survives power loss, costs a disk flush per chunk).
  bool fsync_each_chunk = false;
  /// fsync() once in close(), before reporting success.
  bool fsync_on_close = true;

  /// Throws FieldError ("mcap.chunk_size_bytes = 0: must be > 0") on a bad field.
  void validate() const;
};

/// Writes one MCAP file. Not thread-safe: one thread owns a Writer.
///
/// Every write to the file is checked: an I/O failure (unwritable path, disk
/// full) throws std::runtime_error naming the path and the errno text, and the
/// writer is then failed: further calls throw. close() of a failed writer
/// releases the file and throws again, so a caught error is never mistaken for
/// a complete file.
class Writer {
 public:
  /// Creates (truncates) `path` and writes Magic + Header, flushed.
  /// Throws FieldError on bad options, std::runtime_error "mcap: PATH: errno text" on I/O failure.
  explicit Writer(std::string path, WriterOptions options = {});
  ~Writer();  ///< close() without throwing; errors are swallowed (call close() to see them).
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;

  /// Adds a schema (e.g. name "ddswarm::DroneState", encoding "omgidl", data = IDL text).
  /// Written to the data section at once. Returns its id (1, 2, ...).
  std::uint16_t add_schema(const std::string& name, const std::string& encoding,
                           const std::string& data);

  /// Adds a channel on `topic` (message_encoding e.g. "cdr"); schema_id 0 means no schema.
  /// Written to the data section at once. Returns its id (1, 2, ...).
  /// Throws std::invalid_argument if schema_id is neither 0 nor a returned schema id.
  std::uint16_t add_channel(std::uint16_t schema_id, const std::string& topic,
                            const std::string& message_encoding,
                            const std::map<std::string, std::string>& metadata = {});

  /// Appends one message to the open chunk; closes the chunk when it is full.
  /// Times in ns since the recording's epoch. `sequence` defaults to a per-channel
  /// counter (0, 1, ...). Throws std::invalid_argument on an unknown channel id,
  /// std::logic_error after close, std::runtime_error on I/O failure.
  void write(std::uint16_t channel_id, std::uint64_t log_time_ns, std::uint64_t publish_time_ns,
             const std::uint8_t* data, std::size_t n,
             std::optional<std::uint32_t> sequence = std::nullopt);

  /// Writes the open chunk (if it holds any message) and its message indexes, then fflush()es.
  void flush_chunk();

  /// Finishes the file: last chunk, DataEnd, summary, footer, magic, fsync, fclose.
  /// Idempotent; throws std::runtime_error on I/O failure (see class comment).
  void close();

  const std::string& path() const { return path_; }
  bool is_open() const { return file_ != nullptr; }
  std::uint64_t messages_written() const { return message_count_; }
  /// Bytes handed to the file so far (the file size once closed).
  std::uint64_t bytes_written() const { return offset_; }
  /// Message payload bytes written (sum of `n`).
  std::uint64_t payload_bytes_written() const { return payload_bytes_; }
  std::uint64_t chunks_written() const { return chunk_indexes_.size(); }

 private:
  struct SchemaRec {
    std::uint16_t id;
    std::string name, encoding, data;
  };
  struct ChannelRec {
    std::uint16_t id, schema_id;
    std::string topic, message_encoding;
    std::map<std::string, std::string> metadata;
  };
  struct ChunkIndexRec {
    std::uint64_t start_ns, end_ns, offset, length;
    std::vector<std::pair<std::uint16_t, std::uint64_t>> index_offsets;
    std::uint64_t index_length, compressed_size, uncompressed_size;
  };

  /// Schema / Channel record into scratch_ (data section and summary alike).
  void encode(const SchemaRec& s);
  void encode(const ChannelRec& c);
  void emit(const std::uint8_t* p, std::size_t n);
  void emit(const std::vector<std::uint8_t>& v) { emit(v.data(), v.size()); }
  void flush_file();
  [[noreturn]] void fail(const std::string& what, int err);
  void check_usable() const;
  void compress_chunk();

  std::string path_;
  WriterOptions opt_;
  std::FILE* file_ = nullptr;
  std::string failure_;  // non-empty once an I/O error was thrown
  std::uint64_t offset_ = 0;
  std::uint32_t crc_ = 0;  // running CRC32 of every byte written (data section, then summary)

  std::vector<SchemaRec> schemas_;
  std::vector<ChannelRec> channels_;
  std::vector<std::uint32_t> next_sequence_;   // per channel, index id-1
  std::vector<std::uint64_t> channel_counts_;  // per channel, index id-1
  std::uint64_t message_count_ = 0, payload_bytes_ = 0;
  std::uint64_t start_ns_ = 0, end_ns_ = 0;

  // Open chunk: uncompressed records plus, per channel, (log_time, offset) entries.
  std::vector<std::uint8_t> chunk_;
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunk_index_;
  std::uint64_t chunk_start_ns_ = 0, chunk_end_ns_ = 0;
  std::vector<std::uint8_t> compressed_, scratch_;
  void* zstd_ctx_ = nullptr;

  std::vector<ChunkIndexRec> chunk_indexes_;
};

// ---- Format details shared with the reader ---------------------------------

/// CRC32 (IEEE 802.3 / zlib polynomial), as MCAP uses. Pass the previous
/// result as `crc` to continue over several buffers; start with 0.
std::uint32_t crc32(const std::uint8_t* data, std::size_t n, std::uint32_t crc = 0);

/// The 8 magic bytes that open and close an MCAP file.
inline constexpr std::uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', 0x30, '\r', '\n'};

/// Record opcodes.
enum class Op : std::uint8_t {
  header = 0x01,
  footer = 0x02,
  schema = 0x03,
  channel = 0x04,
  message = 0x05,
  chunk = 0x06,
  message_index = 0x07,
  chunk_index = 0x08,
  attachment = 0x09,
  attachment_index = 0x0A,
  statistics = 0x0B,
  metadata = 0x0C,
  metadata_index = 0x0D,
  summary_offset = 0x0E,
  data_end = 0x0F,
};

}  // namespace ddswarm::mcap
