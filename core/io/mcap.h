#pragma once

#include <cstdint>
#include <fstream>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "core/types/status.h"

namespace stcalib {

// MCAP, the default storage of ROS 2 bags since Iron (the format: https://mcap.dev/spec, major
// version 0). Only reading, and only what a calibration needs: the channels (topic, message
// encoding, schema name) and the messages of the data section in file order, from chunks that
// are uncompressed, zstd or lz4 (LZ4 frame) compressed. Index, attachment, metadata and statistics
// records are skipped; the summary section is not read (a linear pass needs none of it).

struct McapChannel {
  uint16_t id = 0;
  std::string topic;
  std::string message_encoding;  ///< "cdr" in ROS 2 bags
  std::string schema_name;       ///< e.g. "sensor_msgs/msg/Image"; empty without a schema
  std::string schema_encoding;   ///< e.g. "ros2msg"
};

struct McapMessage {
  uint16_t channel_id = 0;
  uint32_t sequence = 0;
  uint64_t log_time_ns = 0;      ///< when it was recorded [ns]
  uint64_t publish_time_ns = 0;  ///< when it was published [ns]
  std::vector<uint8_t> data;     ///< the serialized message (CDR in ROS 2 bags)
};

struct McapSummary {
  std::string profile;                         ///< the Header's ("ros2" for ROS 2 bags)
  std::map<uint16_t, McapChannel> channels;    ///< every channel met, by id
  std::map<uint16_t, uint64_t> message_count;  ///< messages read per channel id
  // Empty when the data section was read to its end; otherwise where and why reading stopped
  // (a truncated or corrupt file): the messages before that point were delivered.
  std::string stopped;
};

// Called for every message, in file order, with its channel (already known: MCAP writes a
// channel before its first message).
using McapVisitor = std::function<void(const McapChannel&, const McapMessage&)>;

// Reads `path` from start to end, one record at a time (its memory is the largest record's: a
// chunk, or a message outside chunks). Errors name the file: missing, not an MCAP
// file (its magic), an unsupported major version or chunk compression, a message on an unknown
// channel. A file cut short or with a record that runs past its end is not an error: the messages
// before the fault are delivered and `summary->stopped` says at which byte and why.
Status ReadMcap(const std::string& path, const McapVisitor& visit, McapSummary* summary);

// The same over bytes in memory; `name` stands for the file in messages.
Status ParseMcap(const std::vector<uint8_t>& bytes, const std::string& name,
                 const McapVisitor& visit, McapSummary* summary);

// Writes an MCAP file for ROS 2 (profile "ros2"): the schemas and channels, then each message as
// a record of the data section, unchunked and uncompressed, then DataEnd and a Footer without a
// summary section (readers that need one scan the file; the CRCs are zero, "not computed").
class McapWriter {
 public:
  McapWriter() = default;
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;
  ~McapWriter();
  Status Open(const std::string& path);
  // A ROS 2 message type ("sensor_msgs/msg/Image") with its definition in ros2msg text.
  uint16_t AddSchema(const std::string& name, const std::string& ros2msg_definition);
  uint16_t AddChannel(uint16_t schema_id, const std::string& topic);  ///< CDR messages
  void Write(uint16_t channel_id, uint64_t log_time_ns, const std::vector<uint8_t>& cdr);
  // Closes the data section; an error names the file when any write failed.
  Status Close();
  uint64_t messages_written() const { return messages_; }

 private:
  void Record(uint8_t opcode, const std::vector<uint8_t>& content);
  std::string path_;
  std::ofstream out_;
  uint16_t next_schema_ = 1, next_channel_ = 0;
  std::map<uint16_t, uint32_t> sequence_;
  uint64_t messages_ = 0;
};

}  // namespace stcalib
