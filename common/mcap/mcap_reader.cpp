#include "common/mcap/mcap_reader.hpp"

#include <fcntl.h>
#include <lz4frame.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zstd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <memory>
#include <stdexcept>

namespace ddswarm::mcap {
namespace {

constexpr std::uint64_t kRecordHead = 1 + 8;  // opcode + content length
constexpr std::uint64_t kFooterRecord = kRecordHead + 8 + 8 + 4;
constexpr std::uint64_t kMaxChunkBytes = std::uint64_t(4) << 30;  // refuse absurd sizes

std::uint64_t le(const std::uint8_t* p, int bytes) {
  std::uint64_t v = 0;
  for (int i = bytes - 1; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

// Bounds-checked little-endian field reader over one record's content.
class Cursor {
 public:
  explicit Cursor(std::span<const std::uint8_t> s) : s_(s) {}
  std::uint8_t u8() { return std::uint8_t(take(1)); }
  std::uint16_t u16() { return std::uint16_t(take(2)); }
  std::uint32_t u32() { return std::uint32_t(take(4)); }
  std::uint64_t u64() { return take(8); }
  std::span<const std::uint8_t> bytes(std::uint64_t n) {
    need(n);
    auto r = s_.subspan(pos_, n);
    pos_ += n;
    return r;
  }
  std::string str() {
    auto b = bytes(u32());
    return std::string(b.begin(), b.end());
  }
  std::span<const std::uint8_t> rest() { return bytes(s_.size() - pos_); }
  std::size_t remaining() const { return s_.size() - pos_; }

 private:
  void need(std::uint64_t n) const {
    if (n > s_.size() - pos_) throw std::runtime_error("record field runs past the record's end");
  }
  std::uint64_t take(int n) {
    need(n);
    auto v = le(s_.data() + pos_, n);
    pos_ += n;
    return v;
  }
  std::span<const std::uint8_t> s_;
  std::size_t pos_ = 0;
};

Schema parse_schema(Cursor c) {
  Schema s;
  s.id = c.u16();
  s.name = c.str();
  s.encoding = c.str();
  s.data = c.str();
  return s;
}

Channel parse_channel(Cursor c) {
  Channel ch;
  ch.id = c.u16();
  ch.schema_id = c.u16();
  ch.topic = c.str();
  ch.message_encoding = c.str();
  Cursor map(c.bytes(c.u32()));
  while (map.remaining()) {
    std::string k = map.str();
    ch.metadata[k] = map.str();
  }
  return ch;
}

MessageView parse_message(Cursor c) {
  MessageView m;
  m.channel_id = c.u16();
  m.sequence = c.u32();
  m.log_time_ns = c.u64();
  m.publish_time_ns = c.u64();
  m.data = c.rest();
  return m;
}

void count_message(Statistics& st, const MessageView& m) {
  if (st.message_count == 0) {
    st.message_start_time_ns = st.message_end_time_ns = m.log_time_ns;
  } else {
    st.message_start_time_ns = std::min(st.message_start_time_ns, m.log_time_ns);
    st.message_end_time_ns = std::max(st.message_end_time_ns, m.log_time_ns);
  }
  ++st.message_count;
  ++st.channel_message_counts[m.channel_id];
}

// Calls fn(op, content) for each record in a chunk's uncompressed records.
template <class Fn>
void for_each_record(std::span<const std::uint8_t> records, Fn&& fn) {
  std::uint64_t pos = 0;
  while (pos < records.size()) {
    if (records.size() - pos < kRecordHead)
      throw std::runtime_error("record header cut short inside the chunk");
    const auto op = records[pos];
    const auto len = le(records.data() + pos + 1, 8);
    if (len > records.size() - pos - kRecordHead)
      throw std::runtime_error("record runs past the chunk's end");
    fn(op, records.subspan(pos + kRecordHead, len));
    pos += kRecordHead + len;
  }
}

// What Reader::corrupt throws: already names the file, so it passes through
// the handlers that add context to lower-level errors.
class FileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

std::string hex(std::uint32_t v) {
  char b[16];
  std::snprintf(b, sizeof b, "0x%08x", v);
  return b;
}

}  // namespace

std::string ReadMode::describe() const {
  if (from_summary) return "summary";
  std::string s = truncated ? "scanned, truncated after " + std::to_string(valid_bytes) + " bytes"
                            : "scanned, complete";
  if (!note.empty()) s += " (" + note + ")";
  return s;
}

Reader::Reader(std::string path) : path_(std::move(path)) {
  fd_ = ::open(path_.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0)
    throw std::runtime_error("mcap: " + path_ + ": cannot open: " + std::strerror(errno));
  try {
    struct stat st {};
    if (::fstat(fd_, &st) != 0) corrupt(std::string("cannot stat: ") + std::strerror(errno));
    const auto size = std::uint64_t(st.st_size);
    std::uint8_t magic[8] = {};
    if (size < sizeof magic) corrupt("not an MCAP file (shorter than the magic)");
    read_at(0, magic, sizeof magic);
    if (std::memcmp(magic, kMagic, sizeof magic) != 0) corrupt("not an MCAP file (bad magic)");
    if (!read_summary(size)) scan(size);
  } catch (...) {
    ::close(fd_);
    throw;
  }
}

Reader::~Reader() {
  if (fd_ >= 0) ::close(fd_);
}

void Reader::corrupt(const std::string& what) const {
  throw FileError("mcap: " + path_ + ": " + what);
}

void Reader::read_at(std::uint64_t offset, std::uint8_t* dst, std::size_t n) const {
  while (n > 0) {
    const ssize_t r = ::pread(fd_, dst, n, off_t(offset));
    if (r < 0) {
      if (errno == EINTR) continue;
      corrupt("read failed at offset " + std::to_string(offset) + ": " + std::strerror(errno));
    }
    if (r == 0) corrupt("unexpected end of file at offset " + std::to_string(offset));
    dst += r;
    n -= std::size_t(r);
    offset += std::uint64_t(r);
  }
}

std::vector<std::uint8_t> Reader::read_vec(std::uint64_t offset, std::uint64_t n) const {
  std::vector<std::uint8_t> v(n);
  read_at(offset, v.data(), v.size());
  return v;
}

const Channel* Reader::channel(std::uint16_t id) const {
  auto it = channels_.find(id);
  return it == channels_.end() ? nullptr : &it->second;
}

bool Reader::read_summary(std::uint64_t size) {
  if (size < sizeof kMagic * 2 + kFooterRecord) {
    mode_.note = "file too short for a footer";
    return false;
  }
  const std::uint64_t footer_at = size - sizeof kMagic - kFooterRecord;
  const auto tail = read_vec(footer_at, kFooterRecord + sizeof kMagic);
  if (std::memcmp(tail.data() + kFooterRecord, kMagic, sizeof kMagic) != 0) {
    mode_.note = "no trailing magic: writer not closed";
    return false;
  }
  if (tail[0] != std::uint8_t(Op::footer) ||
      le(tail.data() + 1, 8) != kFooterRecord - kRecordHead) {
    mode_.note = "no footer record";
    return false;
  }
  const auto summary_start = le(tail.data() + 9, 8);
  const auto summary_crc = std::uint32_t(le(tail.data() + 25, 4));
  if (summary_start == 0) {
    mode_.note = "footer has no summary";
    return false;
  }
  if (summary_start < sizeof kMagic || summary_start > footer_at) {
    mode_.note = "footer's summary offset lies outside the file";
    return false;
  }
  // Summary and summary offset sections, then the footer prefix the CRC covers.
  const auto summary = read_vec(summary_start, footer_at - summary_start + 1 + 8 + 8 + 8);
  if (summary_crc != 0) {
    const auto crc = crc32(summary.data(), summary.size());
    if (crc != summary_crc) {
      mode_.note =
          "summary CRC mismatch (stored " + hex(summary_crc) + ", computed " + hex(crc) + ")";
      return false;
    }
  }
  std::map<std::uint16_t, Schema> schemas;
  std::map<std::uint16_t, Channel> channels;
  std::vector<ChunkInfo> chunks;
  Statistics stats;
  bool have_stats = false;
  try {
    // The header is read here too, so a summary read never scans the data section.
    std::uint8_t head[kRecordHead];
    read_at(sizeof kMagic, head, sizeof head);
    if (head[0] != std::uint8_t(Op::header)) throw std::runtime_error("no Header record");
    const auto header_len = le(head + 1, 8);
    if (header_len > summary_start) throw std::runtime_error("Header record too long");
    const auto header = read_vec(sizeof kMagic + kRecordHead, header_len);
    Cursor h(header);
    profile_ = h.str();
    library_ = h.str();

    std::span<const std::uint8_t> records(summary.data(), footer_at - summary_start);
    for_each_record(records, [&](std::uint8_t op, std::span<const std::uint8_t> content) {
      Cursor c(content);
      switch (Op(op)) {
        case Op::schema: {
          auto s = parse_schema(c);
          if (s.id != 0) schemas[s.id] = std::move(s);
          break;
        }
        case Op::channel: {
          auto ch = parse_channel(c);
          channels[ch.id] = std::move(ch);
          break;
        }
        case Op::statistics: {
          have_stats = true;
          stats.message_count = c.u64();
          stats.schema_count = c.u16();
          stats.channel_count = c.u32();
          c.u32();  // attachments
          c.u32();  // metadata
          stats.chunk_count = c.u32();
          stats.message_start_time_ns = c.u64();
          stats.message_end_time_ns = c.u64();
          Cursor map(c.bytes(c.u32()));
          while (map.remaining()) {
            const auto id = map.u16();
            stats.channel_message_counts[id] = map.u64();
          }
          break;
        }
        case Op::chunk_index: {
          ChunkInfo ci;
          ci.message_start_time_ns = c.u64();
          ci.message_end_time_ns = c.u64();
          ci.offset = c.u64();
          ci.length = c.u64();
          c.bytes(c.u32());  // message index offsets: not needed to read every message
          c.u64();           // message index length
          ci.compression = c.str();
          ci.compressed_size = c.u64();
          ci.uncompressed_size = c.u64();
          if (ci.offset < sizeof kMagic || ci.length < kRecordHead || ci.offset > summary_start ||
              ci.length > summary_start - ci.offset)
            throw std::runtime_error("chunk index points outside the data section");
          chunks.push_back(std::move(ci));
          break;
        }
        default:
          break;  // summary offsets, attachment/metadata indexes, unknown opcodes
      }
    });
  } catch (const std::exception& e) {
    mode_.note = std::string("summary unreadable: ") + e.what();
    profile_.clear();
    library_.clear();
    return false;
  }
  if (chunks.empty() && (!have_stats || stats.message_count > 0)) {
    mode_.note = "summary indexes no chunk";
    return false;
  }
  std::sort(chunks.begin(), chunks.end(),
            [](const ChunkInfo& a, const ChunkInfo& b) { return a.offset < b.offset; });
  schemas_ = std::move(schemas);
  channels_ = std::move(channels);
  chunks_ = std::move(chunks);
  items_.clear();
  for (const auto& c : chunks_) items_.push_back({true, c.offset, c.length});
  mode_ = ReadMode{};
  mode_.from_summary = true;
  if (have_stats) {
    stats_ = std::move(stats);
  } else {
    for_each_message([&](const MessageView& m) { count_message(stats_, m); });
    stats_.schema_count = std::uint16_t(schemas_.size());
    stats_.channel_count = std::uint32_t(channels_.size());
    stats_.chunk_count = std::uint32_t(chunks_.size());
  }
  return true;
}

void Reader::scan(std::uint64_t size) {
  schemas_.clear();
  channels_.clear();
  chunks_.clear();
  items_.clear();
  stats_ = Statistics{};
  mode_.from_summary = false;

  std::uint64_t pos = sizeof kMagic;
  std::uint32_t crc = crc32(kMagic, sizeof kMagic);
  bool complete = false;
  std::string stop;
  std::vector<std::uint8_t> content, records;
  while (true) {
    if (pos == size) {
      stop = "file ends before Data End";
      break;
    }
    if (size - pos < kRecordHead) {
      stop = "record header at offset " + std::to_string(pos) + " cut short";
      break;
    }
    std::uint8_t head[kRecordHead];
    read_at(pos, head, sizeof head);
    const std::uint8_t op = head[0];
    const std::uint64_t len = le(head + 1, 8);
    if (op == 0) {
      stop = "invalid opcode 0 at offset " + std::to_string(pos);
      break;
    }
    if (len > size - pos - kRecordHead) {
      stop = "record (opcode " + std::to_string(op) + ") at offset " + std::to_string(pos) +
             " cut short";
      break;
    }
    if (Op(op) == Op::footer) {  // no Data End (not spec-conformant, but harmless)
      complete = true;
      break;
    }
    content.resize(len);
    read_at(pos + kRecordHead, content.data(), content.size());
    if (Op(op) == Op::data_end) {
      Cursor c(content);
      const auto stored = c.remaining() >= 4 ? c.u32() : 0;
      if (stored != 0 && stored != crc)
        corrupt("data section CRC mismatch (stored " + hex(stored) + ", computed " + hex(crc) +
                ")");
      pos += kRecordHead + len;
      complete = true;
      break;
    }
    crc = crc32(head, sizeof head, crc);
    crc = crc32(content.data(), content.size(), crc);

    auto on_record = [&](std::uint8_t rop, std::span<const std::uint8_t> body) {
      Cursor c(body);
      switch (Op(rop)) {
        case Op::schema: {
          auto s = parse_schema(c);
          if (s.id != 0) schemas_[s.id] = std::move(s);
          break;
        }
        case Op::channel: {
          auto ch = parse_channel(c);
          stats_.channel_message_counts.try_emplace(ch.id, 0);
          channels_[ch.id] = std::move(ch);
          break;
        }
        case Op::message:
          count_message(stats_, parse_message(c));
          break;
        default:
          break;
      }
    };
    try {
      switch (Op(op)) {
        case Op::header:
          if (pos == sizeof kMagic) {
            Cursor c(content);
            profile_ = c.str();
            library_ = c.str();
          }
          break;
        case Op::schema:
        case Op::channel:
          on_record(op, content);
          break;
        case Op::message:
          on_record(op, content);
          items_.push_back({false, pos, kRecordHead + len});
          break;
        case Op::chunk: {
          chunk_records(pos, content, records);
          Cursor c(content);
          ChunkInfo ci;
          ci.offset = pos;
          ci.length = kRecordHead + len;
          ci.message_start_time_ns = c.u64();
          ci.message_end_time_ns = c.u64();
          ci.uncompressed_size = c.u64();
          c.u32();
          ci.compression = c.str();
          ci.compressed_size = c.u64();
          try {
            for_each_record(records, on_record);
          } catch (const FileError&) {
            throw;
          } catch (const std::runtime_error& e) {
            corrupt("chunk at offset " + std::to_string(pos) + ": " + e.what());
          }
          chunks_.push_back(std::move(ci));
          items_.push_back({true, pos, kRecordHead + len});
          break;
        }
        default:
          break;  // message indexes, attachments, metadata, unknown records
      }
    } catch (const FileError&) {
      throw;
    } catch (const std::runtime_error& e) {
      corrupt("record (opcode " + std::to_string(op) + ") at offset " + std::to_string(pos) + ": " +
              e.what());
    }
    pos += kRecordHead + len;
  }
  mode_.truncated = !complete;
  mode_.valid_bytes = pos;
  if (!stop.empty()) mode_.note += (mode_.note.empty() ? "" : "; ") + stop;
  stats_.schema_count = std::uint16_t(schemas_.size());
  stats_.channel_count = std::uint32_t(channels_.size());
  stats_.chunk_count = std::uint32_t(chunks_.size());
}

void Reader::chunk_records(std::uint64_t offset, std::span<const std::uint8_t> content,
                           std::vector<std::uint8_t>& out) const {
  const std::string where = "chunk at offset " + std::to_string(offset) + ": ";
  try {
    Cursor c(content);
    c.u64();  // message start time
    c.u64();  // message end time
    const auto uncompressed_size = c.u64();
    const auto stored_crc = c.u32();
    const auto compression = c.str();
    const auto records = c.bytes(c.u64());
    if (uncompressed_size > kMaxChunkBytes)
      throw std::runtime_error("uncompressed size " + std::to_string(uncompressed_size) +
                               " is implausible");
    if (compression.empty()) {
      if (records.size() != uncompressed_size)
        throw std::runtime_error("uncompressed chunk size does not match its records");
      out.assign(records.begin(), records.end());
    } else if (compression == "zstd") {
      out.resize(uncompressed_size);
      const auto r = ZSTD_decompress(out.data(), out.size(), records.data(), records.size());
      if (ZSTD_isError(r)) throw std::runtime_error(std::string("zstd: ") + ZSTD_getErrorName(r));
      if (r != uncompressed_size) throw std::runtime_error("zstd: decompressed size mismatch");
    } else if (compression == "lz4") {
      out.resize(uncompressed_size);
      LZ4F_dctx* raw = nullptr;
      if (LZ4F_isError(LZ4F_createDecompressionContext(&raw, LZ4F_VERSION)))
        throw std::runtime_error("lz4: cannot create a decompression context");
      std::unique_ptr<LZ4F_dctx, decltype(&LZ4F_freeDecompressionContext)> dctx(
          raw, &LZ4F_freeDecompressionContext);
      std::size_t in_pos = 0, out_pos = 0, hint = 1;
      while (hint != 0) {
        std::size_t in_n = records.size() - in_pos, out_n = out.size() - out_pos;
        hint = LZ4F_decompress(dctx.get(), out.data() + out_pos, &out_n, records.data() + in_pos,
                               &in_n, nullptr);
        if (LZ4F_isError(hint))
          throw std::runtime_error(std::string("lz4: ") + LZ4F_getErrorName(hint));
        in_pos += in_n;
        out_pos += out_n;
        if (hint != 0 && in_n == 0 && out_n == 0)
          throw std::runtime_error("lz4: frame incomplete or larger than its stated size");
      }
      if (out_pos != uncompressed_size) throw std::runtime_error("lz4: decompressed size mismatch");
    } else {
      throw std::runtime_error("unsupported compression '" + compression + "'");
    }
    if (stored_crc != 0) {
      const auto crc = crc32(out.data(), out.size());
      if (crc != stored_crc)
        throw std::runtime_error("CRC mismatch (stored " + hex(stored_crc) + ", computed " +
                                 hex(crc) + ")");
    }
  } catch (const FileError&) {
    throw;
  } catch (const std::runtime_error& e) {
    corrupt(where + e.what());
  }
}

void Reader::for_each_message(const std::function<void(const MessageView&)>& fn) const {
  std::vector<std::uint8_t> records;
  std::vector<MessageView> views;
  for (const auto& item : items_) {
    const auto rec = read_vec(item.offset, item.length);
    const std::span<const std::uint8_t> content(rec.data() + kRecordHead, rec.size() - kRecordHead);
    const auto expected = item.is_chunk ? Op::chunk : Op::message;
    if (rec[0] != std::uint8_t(expected) || le(rec.data() + 1, 8) != content.size())
      corrupt("no " + std::string(item.is_chunk ? "chunk" : "message") + " record at offset " +
              std::to_string(item.offset));
    if (!item.is_chunk) {
      fn(parse_message(Cursor(content)));
      continue;
    }
    chunk_records(item.offset, content, records);
    views.clear();
    try {
      for_each_record(records, [&](std::uint8_t op, std::span<const std::uint8_t> body) {
        if (Op(op) == Op::message) views.push_back(parse_message(Cursor(body)));
      });
    } catch (const std::runtime_error& e) {
      corrupt("chunk at offset " + std::to_string(item.offset) + ": " + e.what());
    }
    auto by_time = [](const MessageView& a, const MessageView& b) {
      return a.log_time_ns < b.log_time_ns;
    };
    if (!std::is_sorted(views.begin(), views.end(), by_time))
      std::stable_sort(views.begin(), views.end(), by_time);
    for (const auto& v : views) fn(v);
  }
}

std::vector<Message> Reader::read_messages() const {
  std::vector<Message> out;
  out.reserve(stats_.message_count);
  for_each_message([&](const MessageView& m) {
    out.push_back({m.channel_id, m.sequence, m.log_time_ns, m.publish_time_ns,
                   std::vector<std::uint8_t>(m.data.begin(), m.data.end())});
  });
  return out;
}

}  // namespace ddswarm::mcap
