#pragma once
// A small MCAP reader (https://mcap.dev/spec), the counterpart of Writer.
//
// Opening a file reads its summary when the footer, summary and summary CRC
// are intact (fast: the data section is not touched). Otherwise, e.g. after
// the recorder crashed, it scans the data section record by record and stops
// at the first incomplete or invalid record: everything before it (every
// complete chunk) is available, and statistics are computed from it.
// how_read() says which happened.
//
// Chunks compressed with zstd, lz4 (frame format) or not at all are read; each
// chunk's uncompressed CRC is verified when non-zero.
#include <cstdint>
#include <functional>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "common/mcap/mcap_writer.hpp"

namespace ddswarm::mcap {

struct Schema {
  std::uint16_t id = 0;
  std::string name;
  std::string encoding;  ///< e.g. "omgidl"
  std::string data;      ///< e.g. the IDL text
};

struct Channel {
  std::uint16_t id = 0;
  std::uint16_t schema_id = 0;  ///< 0: no schema
  std::string topic;
  std::string message_encoding;  ///< e.g. "cdr"
  std::map<std::string, std::string> metadata;
};

/// One message; `data` points into a buffer valid only during the callback.
struct MessageView {
  std::uint16_t channel_id = 0;
  std::uint32_t sequence = 0;
  std::uint64_t log_time_ns = 0;
  std::uint64_t publish_time_ns = 0;
  std::span<const std::uint8_t> data;
};

/// An owning copy of a message.
struct Message {
  std::uint16_t channel_id = 0;
  std::uint32_t sequence = 0;
  std::uint64_t log_time_ns = 0;
  std::uint64_t publish_time_ns = 0;
  std::vector<std::uint8_t> data;
};

/// File statistics, from the Statistics record or computed by the scan.
struct Statistics {
  std::uint64_t message_count = 0;
  std::uint16_t schema_count = 0;
  std::uint32_t channel_count = 0;
  std::uint32_t chunk_count = 0;
  std::uint64_t message_start_time_ns = 0;  ///< earliest log time; 0 if no message
  std::uint64_t message_end_time_ns = 0;    ///< latest log time; 0 if no message
  std::map<std::uint16_t, std::uint64_t> channel_message_counts;
};

/// Where a chunk lies in the file.
struct ChunkInfo {
  std::uint64_t offset = 0;  ///< of the Chunk record (its opcode byte)
  std::uint64_t length = 0;  ///< of the whole Chunk record
  std::uint64_t message_start_time_ns = 0;
  std::uint64_t message_end_time_ns = 0;
  std::string compression;
  std::uint64_t compressed_size = 0;
  std::uint64_t uncompressed_size = 0;
};

/// How the file was read.
struct ReadMode {
  bool from_summary = false;      ///< summary used; otherwise the data section was scanned
  bool truncated = false;         ///< scan stopped at an incomplete/invalid record
  std::uint64_t valid_bytes = 0;  ///< scan: bytes of complete records from the file start
  std::string note;               ///< why the summary was not used (empty if it was)
  /// "summary", "scanned, truncated after N bytes (why)" or "scanned, complete (why)".
  std::string describe() const;
};

/// Reads one MCAP file. Non-copyable; all reads are const and re-read the file.
class Reader {
 public:
  /// Opens and indexes `path`. Throws std::runtime_error naming the path when it
  /// cannot be opened, lacks the leading magic, or holds a corrupt chunk met
  /// while scanning (message names the chunk offset).
  explicit Reader(std::string path);
  ~Reader();
  Reader(const Reader&) = delete;
  Reader& operator=(const Reader&) = delete;

  const std::string& path() const { return path_; }
  const ReadMode& how_read() const { return mode_; }
  const std::map<std::uint16_t, Schema>& schemas() const { return schemas_; }
  const std::map<std::uint16_t, Channel>& channels() const { return channels_; }
  const Statistics& statistics() const { return stats_; }
  const std::vector<ChunkInfo>& chunks() const { return chunks_; }
  std::string header_profile() const { return profile_; }
  std::string header_library() const { return library_; }

  /// The channel with this id, or nullptr.
  const Channel* channel(std::uint16_t id) const;

  /// Calls `fn` for every message: chunk after chunk in file order, each
  /// chunk's messages in log-time order (stable). Throws std::runtime_error
  /// "... chunk at offset N: ..." on a CRC mismatch or undecodable chunk.
  void for_each_message(const std::function<void(const MessageView&)>& fn) const;

  /// Every message, copied (convenience for tools and tests).
  std::vector<Message> read_messages() const;

 private:
  struct Item {  // something in the data section that holds messages
    bool is_chunk;
    std::uint64_t offset, length;  // whole record
  };

  bool read_summary(std::uint64_t file_size);
  void scan(std::uint64_t file_size);
  void read_at(std::uint64_t offset, std::uint8_t* dst, std::size_t n) const;
  std::vector<std::uint8_t> read_vec(std::uint64_t offset, std::uint64_t n) const;
  // Decompresses and checks the chunk record whose content is `content`.
  void chunk_records(std::uint64_t offset, std::span<const std::uint8_t> content,
                     std::vector<std::uint8_t>& out) const;
  [[noreturn]] void corrupt(const std::string& what) const;

  std::string path_;
  int fd_ = -1;
  ReadMode mode_;
  std::string profile_, library_;
  std::map<std::uint16_t, Schema> schemas_;
  std::map<std::uint16_t, Channel> channels_;
  Statistics stats_;
  std::vector<ChunkInfo> chunks_;
  std::vector<Item> items_;
};

}  // namespace ddswarm::mcap
