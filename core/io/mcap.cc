#include "core/io/mcap.h"

#include <lz4frame.h>
#include <zstd.h>

#include <cstring>
#include <fstream>
#include <sstream>

namespace stcalib {
namespace {

constexpr uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
// The spec's record opcodes that a linear read acts on.
enum Opcode : uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kDataEnd = 0x0F,
};
// No chunk of a bag decompresses to more than this: a larger declared size is a corrupt file,
// not an allocation to attempt.
constexpr uint64_t kMaxChunkBytes = uint64_t{1} << 31;

// Little-endian fields of one record's content; every read checks the bounds.
class Fields {
 public:
  Fields(const uint8_t* data, size_t size) : data_(data), size_(size) {}
  bool U16(uint16_t* v) { return Int(v); }
  bool U32(uint32_t* v) { return Int(v); }
  bool U64(uint64_t* v) { return Int(v); }
  bool String(std::string* s) {
    uint32_t n;
    if (!U32(&n) || n > size_ - at_) return false;
    s->assign(reinterpret_cast<const char*>(data_ + at_), n);
    at_ += n;
    return true;
  }
  // A byte array prefixed by its length (uint32 or uint64 as the record says).
  template <typename Length>
  bool Bytes(const uint8_t** begin, size_t* n) {
    Length length;
    if (!Int(&length) || length > size_ - at_) return false;
    *begin = data_ + at_;
    *n = static_cast<size_t>(length);
    at_ += *n;
    return true;
  }
  const uint8_t* rest() const { return data_ + at_; }
  size_t rest_size() const { return size_ - at_; }

 private:
  template <typename T>
  bool Int(T* v) {
    if (sizeof(T) > size_ - at_) return false;
    T value = 0;
    for (size_t k = 0; k < sizeof(T); ++k) value |= static_cast<T>(data_[at_ + k]) << (8 * k);
    *v = value;
    at_ += sizeof(T);
    return true;
  }
  const uint8_t* data_;
  size_t size_;
  size_t at_ = 0;
};

class Reader {
 public:
  Reader(std::string name, const McapVisitor& visit, McapSummary* summary)
      : name_(std::move(name)), visit_(visit), summary_(summary) {}
  // The last error came from a record that does not parse (a corrupt or cut file), not from an
  // unsupported feature or an inconsistency.
  bool malformed() const { return malformed_; }

  // One record's content. Sets *end at DataEnd and Footer.
  Status Record(uint8_t opcode, const uint8_t* data, size_t size, bool* end) {
    Fields f(data, size);
    switch (opcode) {
      case kHeader: {
        std::string library;
        if (!f.String(&summary_->profile) || !f.String(&library)) return Malformed("Header");
        return Status::Ok();
      }
      case kSchema: {
        uint16_t id;
        std::string name, encoding;
        const uint8_t* schema;
        size_t n;
        if (!f.U16(&id) || !f.String(&name) || !f.String(&encoding) ||
            !f.Bytes<uint32_t>(&schema, &n)) {
          return Malformed("Schema");
        }
        schemas_[id] = {name, encoding};
        return Status::Ok();
      }
      case kChannel: {
        McapChannel channel;
        uint16_t schema_id;
        if (!f.U16(&channel.id) || !f.U16(&schema_id) || !f.String(&channel.topic) ||
            !f.String(&channel.message_encoding)) {
          return Malformed("Channel");
        }
        if (schema_id != 0) {
          const auto it = schemas_.find(schema_id);
          if (it == schemas_.end()) {
            return Status::Error(name_ + ": channel " + std::to_string(channel.id) + " (" +
                                 channel.topic + ") names schema " + std::to_string(schema_id) +
                                 ", which no Schema record before it defines");
          }
          channel.schema_name = it->second.first;
          channel.schema_encoding = it->second.second;
        }
        summary_->channels[channel.id] = channel;
        return Status::Ok();
      }
      case kMessage: {
        McapMessage message;
        if (!f.U16(&message.channel_id) || !f.U32(&message.sequence) ||
            !f.U64(&message.log_time_ns) || !f.U64(&message.publish_time_ns)) {
          return Malformed("Message");
        }
        const auto it = summary_->channels.find(message.channel_id);
        if (it == summary_->channels.end()) {
          return Status::Error(name_ + ": a message on channel " +
                               std::to_string(message.channel_id) +
                               ", which no Channel record before it defines");
        }
        message.data.assign(f.rest(), f.rest() + f.rest_size());
        ++summary_->message_count[message.channel_id];
        visit_(it->second, message);
        return Status::Ok();
      }
      case kChunk:
        return Chunk(&f);
      case kDataEnd:
      case kFooter:
        *end = true;
        return Status::Ok();
      default:  // indexes, attachments, metadata, statistics, summary offsets, extensions
        return Status::Ok();
    }
  }

  // The records inside a chunk, once decompressed.
  Status Chunk(Fields* f) {
    uint64_t start_ns, end_ns, uncompressed_size;
    uint32_t crc;
    std::string compression;
    const uint8_t* records;
    size_t n;
    if (!f->U64(&start_ns) || !f->U64(&end_ns) || !f->U64(&uncompressed_size) || !f->U32(&crc) ||
        !f->String(&compression) || !f->Bytes<uint64_t>(&records, &n)) {
      return Malformed("Chunk");
    }
    std::vector<uint8_t> buffer;
    if (compression.empty()) {
      if (n != uncompressed_size) return Malformed("Chunk (size differs from its records')");
    } else {
      if (uncompressed_size > kMaxChunkBytes) {
        return Malformed("Chunk (declares " + std::to_string(uncompressed_size) + " bytes)");
      }
      buffer.resize(uncompressed_size);
      if (compression == "zstd") {
        const size_t got = ZSTD_decompress(buffer.data(), buffer.size(), records, n);
        if (ZSTD_isError(got) || got != buffer.size()) {
          return Malformed(std::string("zstd chunk (") +
                           (ZSTD_isError(got) ? ZSTD_getErrorName(got) : "wrong size") + ")");
        }
      } else if (compression == "lz4") {
        STCALIB_RETURN_IF_ERROR(Lz4Frame(records, n, &buffer));
      } else {
        return Status::Error(name_ + ": chunk compression \"" + compression +
                             "\" is not supported (only none, zstd and lz4)");
      }
      records = buffer.data();
      n = buffer.size();
    }
    size_t at = 0;
    while (at < n) {
      uint64_t length = 0;
      Fields header(records + at + 1, n - at - 1);
      if (n - at < 9 || !header.U64(&length) || length > n - at - 9) {
        return Malformed("record inside a chunk (runs past the chunk's end)");
      }
      bool end = false;
      STCALIB_RETURN_IF_ERROR(
          Record(records[at], records + at + 9, static_cast<size_t>(length), &end));
      at += 9 + static_cast<size_t>(length);
    }
    return Status::Ok();
  }

 private:
  Status Lz4Frame(const uint8_t* src, size_t n, std::vector<uint8_t>* out) {
    LZ4F_dctx* context = nullptr;
    if (LZ4F_isError(LZ4F_createDecompressionContext(&context, LZ4F_VERSION))) {
      return Status::Error(name_ + ": cannot create an lz4 decompressor");
    }
    size_t written = 0, read = 0;
    size_t hint = 1;
    while (hint != 0 && read < n && written < out->size()) {
      size_t dst_size = out->size() - written, src_size = n - read;
      hint = LZ4F_decompress(context, out->data() + written, &dst_size, src + read, &src_size,
                             nullptr);
      if (LZ4F_isError(hint)) {
        const std::string why = LZ4F_getErrorName(hint);
        LZ4F_freeDecompressionContext(context);
        return Malformed("lz4 chunk (" + why + ")");
      }
      written += dst_size;
      read += src_size;
    }
    LZ4F_freeDecompressionContext(context);
    if (written != out->size()) return Malformed("lz4 chunk (wrong size)");
    return Status::Ok();
  }
  Status Malformed(const std::string& what) {
    malformed_ = true;
    return Status::Error(name_ + ": malformed " + what);
  }

  std::string name_;
  const McapVisitor& visit_;
  McapSummary* summary_;
  std::map<uint16_t, std::pair<std::string, std::string>> schemas_;  // name, encoding
  bool malformed_ = false;
};

// Walks the records of a file of `size` bytes after the leading magic, reading one record at a
// time (a bag is read in the memory of its largest record, not of the file). A record that runs
// past the end, or a file without its closing records, stops the walk with `stopped` set.
Status Walk(std::istream& in, uint64_t size, Reader* reader, McapSummary* summary) {
  uint64_t at = sizeof(kMagic);
  std::vector<uint8_t> content;
  while (true) {
    uint8_t head[9];
    if (size - at < 9 || !in.read(reinterpret_cast<char*>(head), 9)) {
      summary->stopped = "stopped at byte " + std::to_string(at) +
                         ": the file ends before its data section does (truncated)";
      return Status::Ok();
    }
    const uint8_t opcode = head[0];
    Fields header(head + 1, 8);
    uint64_t length;
    header.U64(&length);
    if (length > size - at - 9) {
      summary->stopped = "stopped at byte " + std::to_string(at) + ": a record of " +
                         std::to_string(length) + " bytes runs past the end of the file (" +
                         std::to_string(size - at - 9) + " left): truncated";
      return Status::Ok();
    }
    content.resize(static_cast<size_t>(length));
    if (!in.read(reinterpret_cast<char*>(content.data()), static_cast<std::streamsize>(length))) {
      summary->stopped = "stopped at byte " + std::to_string(at) + ": reading the file failed";
      return Status::Ok();
    }
    bool end = false;
    const Status status = reader->Record(opcode, content.data(), content.size(), &end);
    if (!status.ok()) {
      if (reader->malformed()) {
        summary->stopped = "stopped at byte " + std::to_string(at) + ": " + status.message();
      }
      // A malformed record ends the read like a truncation; an unsupported feature is an error.
      if (!reader->malformed()) return status;
      return Status::Ok();
    }
    if (end) return Status::Ok();
    at += 9 + length;
  }
}

// The magic and version at the start of a file.
Status CheckMagic(const uint8_t* magic, size_t n, const std::string& name) {
  if (n < sizeof(kMagic) || std::memcmp(magic, kMagic, 5) != 0) {
    return Status::Error(name + ": not an MCAP file (no MCAP magic at its start)");
  }
  if (magic[5] != kMagic[5]) {
    return Status::Error(name + ": MCAP major version '" + std::string(1, magic[5]) +
                         "' is not supported (only '0')");
  }
  return Status::Ok();
}

}  // namespace

Status ParseMcap(const std::vector<uint8_t>& bytes, const std::string& name,
                 const McapVisitor& visit, McapSummary* summary) {
  *summary = McapSummary();
  STCALIB_RETURN_IF_ERROR(CheckMagic(bytes.data(), bytes.size(), name));
  std::istringstream in(std::string(bytes.begin(), bytes.end()));
  in.seekg(sizeof(kMagic));
  Reader reader(name, visit, summary);
  return Walk(in, bytes.size(), &reader, summary);
}

Status ReadMcap(const std::string& path, const McapVisitor& visit, McapSummary* summary) {
  *summary = McapSummary();
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return Status::Error(path + ": cannot open the MCAP file");
  const uint64_t size = static_cast<uint64_t>(in.tellg());
  in.seekg(0);
  uint8_t magic[sizeof(kMagic)] = {};
  in.read(reinterpret_cast<char*>(magic), sizeof(magic));
  STCALIB_RETURN_IF_ERROR(CheckMagic(magic, static_cast<size_t>(in.gcount()), path));
  Reader reader(path, visit, summary);
  return Walk(in, size, &reader, summary);
}

namespace {

// Appends little-endian integers and length-prefixed strings and bytes, as MCAP records hold them.
class Appender {
 public:
  explicit Appender(std::vector<uint8_t>* out) : out_(out) {}
  template <typename T>
  Appender& Int(T value) {
    for (size_t k = 0; k < sizeof(T); ++k) out_->push_back(static_cast<uint8_t>(value >> (8 * k)));
    return *this;
  }
  Appender& String(const std::string& s) {
    Int(static_cast<uint32_t>(s.size()));
    out_->insert(out_->end(), s.begin(), s.end());
    return *this;
  }

 private:
  std::vector<uint8_t>* out_;
};

}  // namespace

McapWriter::~McapWriter() {
  if (out_.is_open()) Close();
}

Status McapWriter::Open(const std::string& path) {
  path_ = path;
  out_.open(path, std::ios::binary | std::ios::trunc);
  if (!out_) return Status::Error(path + ": cannot create the MCAP file");
  out_.write(reinterpret_cast<const char*>(kMagic), sizeof(kMagic));
  std::vector<uint8_t> header;
  Appender(&header).String("ros2").String("stcalib");
  Record(kHeader, header);
  return Status::Ok();
}

void McapWriter::Record(uint8_t opcode, const std::vector<uint8_t>& content) {
  std::vector<uint8_t> head;
  Appender(&head).Int(opcode).Int(static_cast<uint64_t>(content.size()));
  out_.write(reinterpret_cast<const char*>(head.data()), static_cast<std::streamsize>(head.size()));
  out_.write(reinterpret_cast<const char*>(content.data()),
             static_cast<std::streamsize>(content.size()));
}

uint16_t McapWriter::AddSchema(const std::string& name, const std::string& ros2msg_definition) {
  const uint16_t id = next_schema_++;
  std::vector<uint8_t> content;
  Appender(&content).Int(id).String(name).String("ros2msg").String(ros2msg_definition);
  Record(kSchema, content);
  return id;
}

uint16_t McapWriter::AddChannel(uint16_t schema_id, const std::string& topic) {
  const uint16_t id = next_channel_++;
  std::vector<uint8_t> content;
  Appender(&content).Int(id).Int(schema_id).String(topic).String("cdr").Int(uint32_t{0});
  Record(kChannel, content);
  return id;
}

void McapWriter::Write(uint16_t channel_id, uint64_t log_time_ns, const std::vector<uint8_t>& cdr) {
  std::vector<uint8_t> content;
  content.reserve(22 + cdr.size());
  Appender(&content).Int(channel_id).Int(sequence_[channel_id]++).Int(log_time_ns).Int(log_time_ns);
  content.insert(content.end(), cdr.begin(), cdr.end());
  Record(kMessage, content);
  ++messages_;
}

Status McapWriter::Close() {
  if (!out_.is_open()) return Status::Ok();
  std::vector<uint8_t> data_end, footer;
  Appender(&data_end).Int(uint32_t{0});  // data section CRC: not computed
  Record(kDataEnd, data_end);
  Appender(&footer).Int(uint64_t{0}).Int(uint64_t{0}).Int(uint32_t{0});  // no summary section
  Record(kFooter, footer);
  out_.write(reinterpret_cast<const char*>(kMagic), sizeof(kMagic));
  out_.close();
  if (!out_) return Status::Error(path_ + ": writing the MCAP file failed (disk full?)");
  return Status::Ok();
}

}  // namespace stcalib
