#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "core/types/status.h"

namespace stcalib {

// A ROS 2 bag: a folder with metadata.yaml and its storage files, MCAP (.mcap, core/io/mcap.h)
// or SQLite (.db3: tables `topics` and `messages` as rosbag2_storage_default_plugins writes
// them). Messages arrive per file in the files' order (metadata.yaml's relative_file_paths, else
// the folder's .mcap and .db3 files by name), in each file by record order (MCAP) or by
// timestamp (SQLite).

struct BagTopic {
  std::string name;                  ///< e.g. "/camera/image_raw"
  std::string type;                  ///< e.g. "sensor_msgs/msg/Image"
  std::string serialization_format;  ///< "cdr"
};

struct BagMessage {
  const BagTopic* topic = nullptr;
  int64_t log_time_ns = 0;  ///< when it was recorded [ns]
  std::vector<uint8_t> data;
};

struct BagSummary {
  std::vector<std::string> files;                 ///< the storage files read, in order
  std::map<std::string, BagTopic> topics;         ///< by name
  std::map<std::string, uint64_t> message_count;  ///< by topic name
  std::string stopped;  ///< where a truncated file stopped (empty when every file was whole)
};

using BagVisitor = std::function<void(const BagMessage&)>;

// Errors name the folder or the file: no storage file, an unreadable SQLite file or one without
// rosbag2's tables, and the MCAP reader's errors.
Status ReadRosbag2(const std::string& folder, const BagVisitor& visit, BagSummary* summary);

// The topics and their types, one per line ("  /topic  [type]"), for a message that names a
// topic the bag does not have.
std::string ListBagTopics(const BagSummary& summary);

}  // namespace stcalib
