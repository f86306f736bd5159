#include "common/mcap/mcap_writer.hpp"

#include <lz4frame.h>
#include <unistd.h>
#include <zstd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "common/config_error.hpp"

namespace ddswarm::mcap {
namespace {

// Slicing-by-8 tables, built at compile time: table[0] is the classic bytewise
// table, table[k] advances a byte through k further zero bytes.
constexpr std::array<std::array<std::uint32_t, 256>, 8> make_crc_tables() {
  std::array<std::array<std::uint32_t, 256>, 8> t{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    t[0][i] = c;
  }
  for (std::size_t i = 0; i < 256; ++i)
    for (std::size_t k = 1; k < 8; ++k) t[k][i] = (t[k - 1][i] >> 8) ^ t[0][t[k - 1][i] & 0xFF];
  return t;
}
constexpr auto kCrcTables = make_crc_tables();

inline std::uint32_t load_le32(const std::uint8_t* p) {
  return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 |
         std::uint32_t(p[3]) << 24;
}

// Little-endian serialisation into a byte buffer.
inline void put_u8(std::vector<std::uint8_t>& b, std::uint8_t v) { b.push_back(v); }
inline void put_le(std::vector<std::uint8_t>& b, std::uint64_t v, int bytes) {
  std::uint8_t tmp[8];
  for (int i = 0; i < bytes; ++i) tmp[i] = std::uint8_t(v >> (8 * i));
  b.insert(b.end(), tmp, tmp + bytes);
}
inline void put_u16(std::vector<std::uint8_t>& b, std::uint16_t v) { put_le(b, v, 2); }
inline void put_u32(std::vector<std::uint8_t>& b, std::uint32_t v) { put_le(b, v, 4); }
inline void put_u64(std::vector<std::uint8_t>& b, std::uint64_t v) { put_le(b, v, 8); }
void put_str(std::vector<std::uint8_t>& b, const std::string& s) {
  if (s.size() > 0xFFFFFFFFu) throw std::length_error("mcap: string longer than 4 GiB");
  put_u32(b, std::uint32_t(s.size()));
  b.insert(b.end(), s.begin(), s.end());
}
// A record is <opcode><u64 content length><content>; the length is patched in
// by end_record once the content is known.
std::size_t begin_record(std::vector<std::uint8_t>& b, Op op) {
  put_u8(b, std::uint8_t(op));
  std::size_t at = b.size();
  put_u64(b, 0);
  return at;
}
void end_record(std::vector<std::uint8_t>& b, std::size_t at) {
  std::uint64_t len = b.size() - at - 8;
  for (int i = 0; i < 8; ++i) b[at + i] = std::uint8_t(len >> (8 * i));
}

}  // namespace

std::uint32_t crc32(const std::uint8_t* p, std::size_t n, std::uint32_t crc) {
  const auto& t = kCrcTables;
  crc = ~crc;
  while (n >= 8) {
    std::uint32_t a = load_le32(p) ^ crc, b = load_le32(p + 4);
    crc = t[7][a & 0xFF] ^ t[6][(a >> 8) & 0xFF] ^ t[5][(a >> 16) & 0xFF] ^ t[4][a >> 24] ^
          t[3][b & 0xFF] ^ t[2][(b >> 8) & 0xFF] ^ t[1][(b >> 16) & 0xFF] ^ t[0][b >> 24];
    p += 8;
    n -= 8;
  }
  while (n--) crc = t[0][(crc ^ *p++) & 0xFF] ^ (crc >> 8);
  return ~crc;
}

const char* compression_name(Compression c) {
  switch (c) {
    case Compression::zstd:
      return "zstd";
    case Compression::lz4:
      return "lz4";
    case Compression::none:
      break;
  }
  return "";
}

void WriterOptions::validate() const {
  check_positive("mcap.chunk_size_bytes", chunk_size_bytes);
  if (compression == Compression::zstd)
    check_range("mcap.compression_level", compression_level, 1, ZSTD_maxCLevel());
  if (compression == Compression::lz4)
    check_range("mcap.compression_level", compression_level, 0, 12);
}

Writer::Writer(std::string path, WriterOptions options)
    : path_(std::move(path)), opt_(std::move(options)) {
  opt_.validate();
  file_ = std::fopen(path_.c_str(), "wb");
  if (!file_)
    throw std::runtime_error("mcap: " + path_ + ": cannot create: " + std::strerror(errno));
  try {
    if (opt_.compression == Compression::zstd) {
      auto* ctx = ZSTD_createCCtx();
      if (!ctx) throw std::bad_alloc();
      zstd_ctx_ = ctx;
      ZSTD_CCtx_setParameter(ctx, ZSTD_c_compressionLevel, opt_.compression_level);
    }
    chunk_.reserve(std::min<std::uint64_t>(opt_.chunk_size_bytes + 65536, 64u << 20));
    emit(kMagic, sizeof kMagic);
    scratch_.clear();
    auto at = begin_record(scratch_, Op::header);
    put_str(scratch_, opt_.profile);
    put_str(scratch_, opt_.library);
    end_record(scratch_, at);
    emit(scratch_);
    flush_file();
  } catch (...) {
    std::fclose(file_);
    file_ = nullptr;
    ZSTD_freeCCtx(static_cast<ZSTD_CCtx*>(zstd_ctx_));
    throw;
  }
}

Writer::~Writer() {
  try {
    close();
  } catch (...) {
    // A destructor must not throw; callers who care call close() themselves.
  }
  ZSTD_freeCCtx(static_cast<ZSTD_CCtx*>(zstd_ctx_));
}

void Writer::fail(const std::string& what, int err) {
  failure_ = "mcap: " + path_ + ": " + what + ": " + std::strerror(err ? err : EIO);
  throw std::runtime_error(failure_);
}

void Writer::check_usable() const {
  if (!failure_.empty()) throw std::runtime_error(failure_ + " (writer unusable after this error)");
  if (!file_) throw std::logic_error("mcap: " + path_ + ": writer is closed");
}

void Writer::emit(const std::uint8_t* p, std::size_t n) {
  check_usable();
  if (n == 0) return;
  if (std::fwrite(p, 1, n, file_) != n) fail("write failed", errno);
  offset_ += n;
  crc_ = crc32(p, n, crc_);
}

void Writer::flush_file() {
  if (std::fflush(file_) != 0) fail("flush failed", errno);
}

void Writer::encode(const SchemaRec& s) {
  scratch_.clear();
  auto at = begin_record(scratch_, Op::schema);
  put_u16(scratch_, s.id);
  put_str(scratch_, s.name);
  put_str(scratch_, s.encoding);
  put_str(scratch_, s.data);  // uint32 length-prefixed bytes: same layout as a string
  end_record(scratch_, at);
}

void Writer::encode(const ChannelRec& c) {
  scratch_.clear();
  auto at = begin_record(scratch_, Op::channel);
  put_u16(scratch_, c.id);
  put_u16(scratch_, c.schema_id);
  put_str(scratch_, c.topic);
  put_str(scratch_, c.message_encoding);
  std::vector<std::uint8_t> map;
  for (const auto& [k, v] : c.metadata) {
    put_str(map, k);
    put_str(map, v);
  }
  put_u32(scratch_, std::uint32_t(map.size()));
  scratch_.insert(scratch_.end(), map.begin(), map.end());
  end_record(scratch_, at);
}

std::uint16_t Writer::add_schema(const std::string& name, const std::string& encoding,
                                 const std::string& data) {
  check_usable();
  if (schemas_.size() >= 0xFFFF) throw std::length_error("mcap: " + path_ + ": too many schemas");
  SchemaRec s{std::uint16_t(schemas_.size() + 1), name, encoding, data};
  encode(s);
  emit(scratch_);
  schemas_.push_back(std::move(s));
  return schemas_.back().id;
}

std::uint16_t Writer::add_channel(std::uint16_t schema_id, const std::string& topic,
                                  const std::string& message_encoding,
                                  const std::map<std::string, std::string>& metadata) {
  check_usable();
  if (schema_id > schemas_.size())
    throw std::invalid_argument("mcap: " + path_ + ": channel '" + topic + "' names schema id " +
                                std::to_string(schema_id) + ", which was never added");
  if (channels_.size() >= 0xFFFF) throw std::length_error("mcap: " + path_ + ": too many channels");
  ChannelRec c{std::uint16_t(channels_.size() + 1), schema_id, topic, message_encoding, metadata};
  encode(c);
  emit(scratch_);
  channels_.push_back(std::move(c));
  next_sequence_.push_back(0);
  channel_counts_.push_back(0);
  return channels_.back().id;
}

void Writer::write(std::uint16_t channel_id, std::uint64_t log_time_ns,
                   std::uint64_t publish_time_ns, const std::uint8_t* data, std::size_t n,
                   std::optional<std::uint32_t> sequence) {
  check_usable();
  if (channel_id == 0 || channel_id > channels_.size())
    throw std::invalid_argument("mcap: " + path_ + ": unknown channel id " +
                                std::to_string(channel_id));
  const std::size_t i = channel_id - 1;
  const std::uint32_t seq = sequence.value_or(next_sequence_[i]);
  next_sequence_[i] = seq + 1;

  const std::uint64_t offset_in_chunk = chunk_.size();
  std::uint8_t head[1 + 8 + 2 + 4 + 8 + 8];
  const std::uint64_t len = 2 + 4 + 8 + 8 + std::uint64_t(n);
  auto le = [](std::uint8_t* p, std::uint64_t v, int bytes) {
    for (int k = 0; k < bytes; ++k) p[k] = std::uint8_t(v >> (8 * k));
  };
  head[0] = std::uint8_t(Op::message);
  le(head + 1, len, 8);
  le(head + 9, channel_id, 2);
  le(head + 11, seq, 4);
  le(head + 15, log_time_ns, 8);
  le(head + 23, publish_time_ns, 8);
  chunk_.insert(chunk_.end(), head, head + sizeof head);
  if (n) chunk_.insert(chunk_.end(), data, data + n);

  auto& entries = chunk_index_[channel_id];
  const bool first_in_chunk = chunk_index_.size() == 1 && entries.empty();
  entries.emplace_back(log_time_ns, offset_in_chunk);
  if (first_in_chunk) {
    chunk_start_ns_ = chunk_end_ns_ = log_time_ns;
  } else {
    chunk_start_ns_ = std::min(chunk_start_ns_, log_time_ns);
    chunk_end_ns_ = std::max(chunk_end_ns_, log_time_ns);
  }
  if (message_count_ == 0) {
    start_ns_ = end_ns_ = log_time_ns;
  } else {
    start_ns_ = std::min(start_ns_, log_time_ns);
    end_ns_ = std::max(end_ns_, log_time_ns);
  }
  ++message_count_;
  ++channel_counts_[i];
  payload_bytes_ += n;

  if (chunk_.size() >= opt_.chunk_size_bytes) flush_chunk();
}

void Writer::compress_chunk() {
  compressed_.clear();
  if (opt_.compression == Compression::zstd) {
    compressed_.resize(ZSTD_compressBound(chunk_.size()));
    const std::size_t r = ZSTD_compress2(static_cast<ZSTD_CCtx*>(zstd_ctx_), compressed_.data(),
                                         compressed_.size(), chunk_.data(), chunk_.size());
    if (ZSTD_isError(r))
      throw std::runtime_error("mcap: " + path_ +
                               ": zstd compression failed: " + ZSTD_getErrorName(r));
    compressed_.resize(r);
  } else if (opt_.compression == Compression::lz4) {
    LZ4F_preferences_t prefs{};
    prefs.frameInfo.contentSize = chunk_.size();
    prefs.compressionLevel = opt_.compression_level;
    compressed_.resize(LZ4F_compressFrameBound(chunk_.size(), &prefs));
    const std::size_t r = LZ4F_compressFrame(compressed_.data(), compressed_.size(), chunk_.data(),
                                             chunk_.size(), &prefs);
    if (LZ4F_isError(r))
      throw std::runtime_error("mcap: " + path_ +
                               ": lz4 compression failed: " + LZ4F_getErrorName(r));
    compressed_.resize(r);
  }
}

void Writer::flush_chunk() {
  check_usable();
  if (chunk_index_.empty()) return;

  const std::uint32_t uncompressed_crc = crc32(chunk_.data(), chunk_.size());
  compress_chunk();
  const bool raw = opt_.compression == Compression::none;
  const std::uint8_t* records = raw ? chunk_.data() : compressed_.data();
  const std::uint64_t records_size = raw ? chunk_.size() : compressed_.size();

  ChunkIndexRec idx{};
  idx.start_ns = chunk_start_ns_;
  idx.end_ns = chunk_end_ns_;
  idx.offset = offset_;
  idx.compressed_size = records_size;
  idx.uncompressed_size = chunk_.size();

  const std::string compression = compression_name(opt_.compression);
  scratch_.clear();
  put_u8(scratch_, std::uint8_t(Op::chunk));
  put_u64(scratch_, 8 + 8 + 8 + 4 + 4 + compression.size() + 8 + records_size);
  put_u64(scratch_, chunk_start_ns_);
  put_u64(scratch_, chunk_end_ns_);
  put_u64(scratch_, chunk_.size());
  put_u32(scratch_, uncompressed_crc);
  put_str(scratch_, compression);
  put_u64(scratch_, records_size);
  emit(scratch_);
  emit(records, records_size);
  idx.length = offset_ - idx.offset;

  const std::uint64_t index_start = offset_;
  for (auto& [channel_id, entries] : chunk_index_) {
    // Readers binary-search these by time; a publisher's clock can step back.
    if (!std::is_sorted(entries.begin(), entries.end(),
                        [](const auto& a, const auto& b) { return a.first < b.first; }))
      std::stable_sort(entries.begin(), entries.end(),
                       [](const auto& a, const auto& b) { return a.first < b.first; });
    idx.index_offsets.emplace_back(channel_id, offset_);
    scratch_.clear();
    auto at = begin_record(scratch_, Op::message_index);
    put_u16(scratch_, channel_id);
    put_u32(scratch_, std::uint32_t(entries.size() * 16));
    for (const auto& [t, off] : entries) {
      put_u64(scratch_, t);
      put_u64(scratch_, off);
    }
    end_record(scratch_, at);
    emit(scratch_);
  }
  idx.index_length = offset_ - index_start;
  chunk_indexes_.push_back(std::move(idx));

  chunk_.clear();
  chunk_index_.clear();
  flush_file();
  if (opt_.fsync_each_chunk && ::fsync(fileno(file_)) != 0 && errno != EINVAL)
    fail("fsync failed", errno);
}

void Writer::close() {
  if (!file_) return;
  if (!failure_.empty()) {
    std::fclose(file_);
    file_ = nullptr;
    throw std::runtime_error(failure_ + " (file left without summary)");
  }
  try {
    flush_chunk();

    const std::uint32_t data_crc = crc_;
    scratch_.clear();
    auto at = begin_record(scratch_, Op::data_end);
    put_u32(scratch_, data_crc);
    end_record(scratch_, at);
    emit(scratch_);

    // Summary: records grouped by opcode, each group indexed by a Summary Offset.
    const std::uint64_t summary_start = offset_;
    crc_ = 0;
    struct Group {
      Op op;
      std::uint64_t start, length;
    };
    std::vector<Group> groups;
    auto group = [&](Op op, std::uint64_t start) {
      if (offset_ > start) groups.push_back({op, start, offset_ - start});
    };

    std::uint64_t start = offset_;
    for (const auto& s : schemas_) {
      encode(s);
      emit(scratch_);
    }
    group(Op::schema, start);

    start = offset_;
    for (const auto& c : channels_) {
      encode(c);
      emit(scratch_);
    }
    group(Op::channel, start);

    start = offset_;
    scratch_.clear();
    at = begin_record(scratch_, Op::statistics);
    put_u64(scratch_, message_count_);
    put_u16(scratch_, std::uint16_t(schemas_.size()));
    put_u32(scratch_, std::uint32_t(channels_.size()));
    put_u32(scratch_, 0);  // attachments
    put_u32(scratch_, 0);  // metadata records
    put_u32(scratch_, std::uint32_t(chunk_indexes_.size()));
    put_u64(scratch_, start_ns_);
    put_u64(scratch_, end_ns_);
    put_u32(scratch_, std::uint32_t(channels_.size() * 10));
    for (std::size_t i = 0; i < channels_.size(); ++i) {
      put_u16(scratch_, channels_[i].id);
      put_u64(scratch_, channel_counts_[i]);
    }
    end_record(scratch_, at);
    emit(scratch_);
    group(Op::statistics, start);

    start = offset_;
    for (const auto& c : chunk_indexes_) {
      scratch_.clear();
      at = begin_record(scratch_, Op::chunk_index);
      put_u64(scratch_, c.start_ns);
      put_u64(scratch_, c.end_ns);
      put_u64(scratch_, c.offset);
      put_u64(scratch_, c.length);
      put_u32(scratch_, std::uint32_t(c.index_offsets.size() * 10));
      for (const auto& [id, off] : c.index_offsets) {
        put_u16(scratch_, id);
        put_u64(scratch_, off);
      }
      put_u64(scratch_, c.index_length);
      put_str(scratch_, compression_name(opt_.compression));
      put_u64(scratch_, c.compressed_size);
      put_u64(scratch_, c.uncompressed_size);
      end_record(scratch_, at);
      emit(scratch_);
    }
    group(Op::chunk_index, start);

    const std::uint64_t summary_offset_start = offset_;
    for (const auto& g : groups) {
      scratch_.clear();
      at = begin_record(scratch_, Op::summary_offset);
      put_u8(scratch_, std::uint8_t(g.op));
      put_u64(scratch_, g.start);
      put_u64(scratch_, g.length);
      end_record(scratch_, at);
      emit(scratch_);
    }

    // The summary CRC covers the footer up to (not including) its own field.
    scratch_.clear();
    put_u8(scratch_, std::uint8_t(Op::footer));
    put_u64(scratch_, 8 + 8 + 4);
    put_u64(scratch_, summary_start);
    put_u64(scratch_, summary_offset_start);
    emit(scratch_);
    scratch_.clear();
    put_u32(scratch_, crc_);
    scratch_.insert(scratch_.end(), kMagic, kMagic + sizeof kMagic);
    emit(scratch_);

    flush_file();
    if (opt_.fsync_on_close && ::fsync(fileno(file_)) != 0 && errno != EINVAL)
      fail("fsync failed", errno);
    std::FILE* f = file_;
    file_ = nullptr;
    if (std::fclose(f) != 0) {
      failure_ = "mcap: " + path_ + ": close failed: " + std::strerror(errno);
      throw std::runtime_error(failure_);
    }
  } catch (...) {
    if (file_) {
      std::fclose(file_);
      file_ = nullptr;
    }
    throw;
  }
}

}  // namespace ddswarm::mcap
