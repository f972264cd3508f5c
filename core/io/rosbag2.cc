#include "core/io/rosbag2.h"

#include <sqlite3.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "core/io/mcap.h"

namespace stcalib {
namespace {

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// metadata.yaml's relative_file_paths (a YAML block list of file names), else the folder's
// storage files by name.
std::vector<std::string> StorageFiles(const std::string& folder) {
  std::vector<std::string> files;
  std::ifstream metadata(folder + "/metadata.yaml");
  std::string line;
  bool in_list = false;
  while (std::getline(metadata, line)) {
    const size_t key = line.find("relative_file_paths:");
    if (key != std::string::npos) {
      in_list = true;
      continue;
    }
    if (!in_list) continue;
    const size_t dash = line.find_first_not_of(' ');
    if (dash == std::string::npos || line[dash] != '-') {
      in_list = false;
      continue;
    }
    std::string name = line.substr(dash + 1);
    name.erase(0, name.find_first_not_of(" \"'"));
    name.erase(name.find_last_not_of(" \"'\r") + 1);
    if (!name.empty()) files.push_back(folder + "/" + name);
  }
  if (!files.empty()) return files;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(folder, ec)) {
    const std::string path = entry.path().string();
    if (EndsWith(path, ".mcap") || EndsWith(path, ".db3")) files.push_back(path);
  }
  std::sort(files.begin(), files.end());
  return files;
}

Status ReadSqlite(const std::string& path, const BagVisitor& visit, BagSummary* summary) {
  sqlite3* db = nullptr;
  if (sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
    const std::string why = db ? sqlite3_errmsg(db) : "out of memory";
    sqlite3_close(db);
    return Status::Error(path + ": cannot open as SQLite (" + why + ")");
  }
  auto fail = [&](const std::string& what) {
    const std::string why = sqlite3_errmsg(db);
    sqlite3_close(db);
    return Status::Error(path + ": " + what + " (" + why + ")");
  };
  std::map<int64_t, const BagTopic*> by_id;
  sqlite3_stmt* statement = nullptr;
  if (sqlite3_prepare_v2(db, "SELECT id, name, type, serialization_format FROM topics", -1,
                         &statement, nullptr) != SQLITE_OK) {
    return fail("not a rosbag2 SQLite file: no table `topics`");
  }
  auto text = [&](int column) {
    const unsigned char* t = sqlite3_column_text(statement, column);
    return t ? std::string(reinterpret_cast<const char*>(t)) : std::string();
  };
  while (sqlite3_step(statement) == SQLITE_ROW) {
    BagTopic topic{text(1), text(2), text(3)};
    BagTopic& stored = summary->topics[topic.name];
    stored = topic;
    by_id[sqlite3_column_int64(statement, 0)] = &stored;
  }
  sqlite3_finalize(statement);
  if (sqlite3_prepare_v2(db, "SELECT topic_id, timestamp, data FROM messages ORDER BY timestamp",
                         -1, &statement, nullptr) != SQLITE_OK) {
    return fail("not a rosbag2 SQLite file: no table `messages`");
  }
  int step;
  while ((step = sqlite3_step(statement)) == SQLITE_ROW) {
    const int64_t topic_id = sqlite3_column_int64(statement, 0);
    const auto topic = by_id.find(topic_id);
    if (topic == by_id.end()) {
      sqlite3_finalize(statement);
      return fail("a message of topic id " + std::to_string(topic_id) +
                  ", which the table `topics` does not have");
    }
    BagMessage message;
    message.topic = topic->second;
    message.log_time_ns = sqlite3_column_int64(statement, 1);
    const auto* blob = static_cast<const uint8_t*>(sqlite3_column_blob(statement, 2));
    message.data.assign(blob, blob + sqlite3_column_bytes(statement, 2));
    ++summary->message_count[message.topic->name];
    visit(message);
  }
  sqlite3_finalize(statement);
  if (step != SQLITE_DONE) {
    summary->stopped = path + ": stopped reading messages (" + sqlite3_errmsg(db) + ")";
  }
  sqlite3_close(db);
  return Status::Ok();
}

Status ReadMcapStorage(const std::string& path, const BagVisitor& visit, BagSummary* summary) {
  std::map<uint16_t, const BagTopic*> by_channel;
  McapSummary mcap;
  const Status status = ReadMcap(
      path,
      [&](const McapChannel& channel, const McapMessage& m) {
        const BagTopic*& topic = by_channel[channel.id];
        if (topic == nullptr) {
          BagTopic& stored = summary->topics[channel.topic];
          stored = {channel.topic, channel.schema_name, channel.message_encoding};
          topic = &stored;
        }
        BagMessage message;
        message.topic = topic;
        message.log_time_ns = static_cast<int64_t>(m.log_time_ns);
        message.data = m.data;
        ++summary->message_count[topic->name];
        visit(message);
      },
      &mcap);
  for (const auto& [id, channel] : mcap.channels) {  // topics that carried no message
    if (summary->topics.count(channel.topic) == 0) {
      summary->topics[channel.topic] = {channel.topic, channel.schema_name,
                                        channel.message_encoding};
    }
  }
  if (!mcap.stopped.empty() && summary->stopped.empty())
    summary->stopped = path + ": " + mcap.stopped;
  return status;
}

}  // namespace

Status ReadRosbag2(const std::string& folder, const BagVisitor& visit, BagSummary* summary) {
  *summary = BagSummary();
  std::error_code ec;
  if (!std::filesystem::is_directory(folder, ec)) {
    return Status::Error(folder + ": not a folder (a ROS 2 bag is a folder with metadata.yaml)");
  }
  summary->files = StorageFiles(folder);
  if (summary->files.empty()) {
    return Status::Error(folder + ": no storage file (.mcap or .db3) in the bag folder");
  }
  for (const std::string& file : summary->files) {
    if (!std::filesystem::is_regular_file(file, ec)) {
      return Status::Error(file + ": listed in metadata.yaml but missing");
    }
    const Status status = EndsWith(file, ".db3") ? ReadSqlite(file, visit, summary)
                                                 : ReadMcapStorage(file, visit, summary);
    if (!status.ok()) return status;
  }
  return Status::Ok();
}

std::string ListBagTopics(const BagSummary& summary) {
  std::string list;
  for (const auto& [name, topic] : summary.topics) {
    const auto count = summary.message_count.find(name);
    list += "  " + name + "  [" + topic.type + "], " +
            std::to_string(count == summary.message_count.end() ? 0 : count->second) +
            " messages\n";
  }
  return list;
}

}  // namespace stcalib
