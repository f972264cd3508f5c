#pragma once

#include <cstdint>
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

// Reads `path` (whole, into memory) from start to end. Errors name the file: missing, not an MCAP
// file (its magic), an unsupported major version or chunk compression, a message on an unknown
// channel. A file cut short or with a record that runs past its end is not an error: the messages
// before the fault are delivered and `summary->stopped` says at which byte and why.
Status ReadMcap(const std::string& path, const McapVisitor& visit, McapSummary* summary);

// The same over bytes in memory; `name` stands for the file in messages.
Status ParseMcap(const std::vector<uint8_t>& bytes, const std::string& name,
                 const McapVisitor& visit, McapSummary* summary);

}  // namespace stcalib
