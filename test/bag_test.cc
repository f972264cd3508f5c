// ROS 2 bag storage: the MCAP reader against byte fixtures written here field by field from the
// MCAP specification (https://mcap.dev/spec), compressed with libzstd and liblz4 themselves.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <lz4frame.h>
#include <sqlite3.h>
#include <zstd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/io/mcap.h"
#include "core/io/ros_messages.h"
#include "core/io/rosbag2.h"
#include "test/test_util.h"

namespace stcalib {
namespace {

using ::testing::HasSubstr;
using Bytes = std::vector<uint8_t>;

// Little-endian fields and records as the specification lays them out.
void PutInt(Bytes* out, uint64_t value, int bytes) {
  for (int k = 0; k < bytes; ++k) out->push_back(static_cast<uint8_t>(value >> (8 * k)));
}
void PutString(Bytes* out, const std::string& s) {
  PutInt(out, s.size(), 4);
  out->insert(out->end(), s.begin(), s.end());
}
void PutRecord(Bytes* out, uint8_t opcode, const Bytes& content) {
  out->push_back(opcode);
  PutInt(out, content.size(), 8);
  out->insert(out->end(), content.begin(), content.end());
}
const Bytes kMagic = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};

Bytes Header() {
  Bytes c;
  PutString(&c, "ros2");
  PutString(&c, "test fixture");
  return c;
}
Bytes Schema(uint16_t id, const std::string& name) {
  Bytes c;
  PutInt(&c, id, 2);
  PutString(&c, name);
  PutString(&c, "ros2msg");
  const std::string text = "uint32 height\nuint32 width\n";
  PutString(&c, text);  // data: uint32 length and bytes, like a string
  return c;
}
Bytes Channel(uint16_t id, uint16_t schema, const std::string& topic) {
  Bytes c;
  PutInt(&c, id, 2);
  PutInt(&c, schema, 2);
  PutString(&c, topic);
  PutString(&c, "cdr");
  Bytes metadata;  // one entry: a map is its byte length, then key and value strings
  PutString(&metadata, "offered_qos_profiles");
  PutString(&metadata, "");
  PutInt(&c, metadata.size(), 4);
  c.insert(c.end(), metadata.begin(), metadata.end());
  return c;
}
Bytes Message(uint16_t channel, uint32_t sequence, uint64_t log_ns, const Bytes& data) {
  Bytes c;
  PutInt(&c, channel, 2);
  PutInt(&c, sequence, 4);
  PutInt(&c, log_ns, 8);
  PutInt(&c, log_ns - 1000, 8);  // published 1 µs before it was logged
  c.insert(c.end(), data.begin(), data.end());
  return c;
}
Bytes Chunk(const Bytes& records, const std::string& compression) {
  Bytes stored = records;
  if (compression == "zstd") {
    stored.resize(ZSTD_compressBound(records.size()));
    stored.resize(ZSTD_compress(stored.data(), stored.size(), records.data(), records.size(), 3));
  } else if (compression == "lz4") {
    stored.resize(LZ4F_compressFrameBound(records.size(), nullptr));
    stored.resize(
        LZ4F_compressFrame(stored.data(), stored.size(), records.data(), records.size(), nullptr));
  } else if (!compression.empty()) {
    stored = Bytes(records.size(), 0x5a);  // an unknown compression: any bytes
  }
  Bytes c;
  PutInt(&c, 100, 8);  // message_start_time
  PutInt(&c, 300, 8);  // message_end_time
  PutInt(&c, records.size(), 8);
  PutInt(&c, 0, 4);  // uncompressed_crc: 0 = not computed
  PutString(&c, compression);
  PutInt(&c, stored.size(), 8);
  c.insert(c.end(), stored.begin(), stored.end());
  return c;
}
// A whole file: magic, header, the data records, an index record the reader must skip, DataEnd,
// a summary section's repeat of the channel, Footer, magic.
Bytes File(const Bytes& data_records) {
  Bytes file = kMagic;
  PutRecord(&file, 0x01, Header());
  file.insert(file.end(), data_records.begin(), data_records.end());
  Bytes index;  // a MessageIndex: channel 1, no entries
  PutInt(&index, 1, 2);
  PutInt(&index, 0, 4);
  PutRecord(&file, 0x07, index);
  Bytes data_end;
  PutInt(&data_end, 0, 4);
  PutRecord(&file, 0x0F, data_end);
  PutRecord(&file, 0x04, Channel(1, 1, "/camera/image_raw"));
  Bytes footer;
  PutInt(&footer, 0, 8);
  PutInt(&footer, 0, 8);
  PutInt(&footer, 0, 4);
  PutRecord(&file, 0x02, footer);
  file.insert(file.end(), kMagic.begin(), kMagic.end());
  return file;
}
// Schemas and channels for an image and a cloud topic.
Bytes SchemasAndChannels() {
  Bytes r;
  PutRecord(&r, 0x03, Schema(1, "sensor_msgs/msg/Image"));
  PutRecord(&r, 0x03, Schema(2, "sensor_msgs/msg/PointCloud2"));
  PutRecord(&r, 0x04, Channel(1, 1, "/camera/image_raw"));
  PutRecord(&r, 0x04, Channel(2, 2, "/lidar/points"));
  return r;
}
// Message records [first, last) of the three: image, cloud, image.
Bytes Messages(int first, int last) {
  const Bytes all[3] = {Message(1, 7, 5000, {1, 2, 3}), Message(2, 8, 6000, {4, 5}),
                        Message(1, 9, 7000, {})};
  Bytes r;
  for (int k = first; k < last; ++k) PutRecord(&r, 0x05, all[k]);
  return r;
}
// The schemas and channels, then the three messages.
Bytes Records() {
  Bytes r = SchemasAndChannels();
  const Bytes messages = Messages(0, 3);
  r.insert(r.end(), messages.begin(), messages.end());
  return r;
}

struct Read {
  Status status = Status::Ok();
  McapSummary summary;
  std::vector<std::string> topics;
  std::vector<McapMessage> messages;
};
Read Parse(const Bytes& file) {
  Read read;
  read.status = ParseMcap(
      file, "fixture.mcap",
      [&](const McapChannel& channel, const McapMessage& message) {
        read.topics.push_back(channel.topic);
        read.messages.push_back(message);
      },
      &read.summary);
  return read;
}

void ExpectTheThreeMessages(const Read& read) {
  ASSERT_TRUE(read.status.ok()) << read.status.message();
  EXPECT_EQ(read.summary.stopped, "");
  EXPECT_EQ(read.summary.profile, "ros2");
  ASSERT_EQ(read.summary.channels.size(), 2u);
  EXPECT_EQ(read.summary.channels.at(1).schema_name, "sensor_msgs/msg/Image");
  EXPECT_EQ(read.summary.channels.at(2).schema_name, "sensor_msgs/msg/PointCloud2");
  EXPECT_EQ(read.summary.channels.at(2).message_encoding, "cdr");
  EXPECT_EQ(read.summary.channels.at(2).schema_encoding, "ros2msg");
  EXPECT_EQ(read.summary.message_count.at(1), 2u);
  ASSERT_EQ(read.messages.size(), 3u);
  EXPECT_EQ(read.topics,
            (std::vector<std::string>{"/camera/image_raw", "/lidar/points", "/camera/image_raw"}));
  EXPECT_EQ(read.messages[0].sequence, 7u);
  EXPECT_EQ(read.messages[0].log_time_ns, 5000u);
  EXPECT_EQ(read.messages[0].publish_time_ns, 4000u);
  EXPECT_EQ(read.messages[0].data, (Bytes{1, 2, 3}));
  EXPECT_EQ(read.messages[1].data, (Bytes{4, 5}));
  EXPECT_TRUE(read.messages[2].data.empty());
}

TEST(Mcap, ReadsRecordsOutsideChunks) { ExpectTheThreeMessages(Parse(File(Records()))); }

TEST(Mcap, ReadsUncompressedZstdAndLz4Chunks) {
  for (const std::string compression : {"", "zstd", "lz4"}) {
    SCOPED_TRACE("compression \"" + compression + "\"");
    Bytes data;
    PutRecord(&data, 0x06, Chunk(Records(), compression));
    ExpectTheThreeMessages(Parse(File(data)));
  }
  // Two chunks, the channels in the first, the messages split across both.
  Bytes first = SchemasAndChannels();
  const Bytes first_message = Messages(0, 1);
  first.insert(first.end(), first_message.begin(), first_message.end());
  const Bytes second = Messages(1, 3);
  Bytes data;
  PutRecord(&data, 0x06, Chunk(first, "zstd"));
  PutRecord(&data, 0x06, Chunk(second, "lz4"));
  ExpectTheThreeMessages(Parse(File(data)));
}

// A file cut anywhere inside its data section delivers the messages before the cut and says
// where it stopped; cut inside a chunk, none of that chunk's.
TEST(Mcap, ATruncatedFileDeliversWhatPrecedesTheCut) {
  const Bytes file = File(Records());
  const size_t records_end = kMagic.size() + 9 + Header().size() + Records().size();
  for (size_t cut = kMagic.size() + 1; cut < records_end; cut += 7) {
    const Read read = Parse(Bytes(file.begin(), file.begin() + cut));
    ASSERT_TRUE(read.status.ok()) << cut << ": " << read.status.message();
    EXPECT_THAT(read.summary.stopped, HasSubstr("stopped at byte")) << cut;
    EXPECT_LE(read.messages.size(), 3u);
    for (size_t k = 0; k < read.messages.size(); ++k) {
      EXPECT_EQ(read.messages[k].sequence, 7u + k);  // in order, none skipped
    }
  }
  Bytes chunked;
  PutRecord(&chunked, 0x06, Chunk(Records(), "zstd"));
  const Bytes whole = File(chunked);
  const Read cut = Parse(Bytes(whole.begin(), whole.begin() + 8 + 9 + Header().size() + 40));
  ASSERT_TRUE(cut.status.ok());
  EXPECT_TRUE(cut.messages.empty());
  EXPECT_THAT(cut.summary.stopped, HasSubstr("runs past the end of the file"));
}

TEST(Mcap, BadInputIsNamed) {
  EXPECT_THAT(Parse(Bytes{'P', 'K', 3, 4, 0, 0, 0, 0, 0}).status.message(),
              HasSubstr("fixture.mcap: not an MCAP file"));
  Bytes version = File(Records());
  version[5] = '1';
  EXPECT_THAT(Parse(version).status.message(), HasSubstr("major version '1'"));
  Bytes brotli;
  PutRecord(&brotli, 0x06, Chunk(Records(), "brotli"));
  EXPECT_THAT(Parse(File(brotli)).status.message(),
              HasSubstr("chunk compression \"brotli\" is not supported"));
  Bytes orphan;
  PutRecord(&orphan, 0x05, Message(4, 1, 100, {1}));
  EXPECT_THAT(Parse(File(orphan)).status.message(),
              HasSubstr("a message on channel 4, which no Channel record before it defines"));
  // A chunk that declares a size its zstd frame does not have: malformed, the read stops there.
  Bytes data;
  Bytes chunk = Chunk(Records(), "zstd");
  chunk[16] ^= 0x01;  // uncompressed_size
  PutRecord(&data, 0x06, chunk);
  const Read bad = Parse(File(data));
  ASSERT_TRUE(bad.status.ok());
  EXPECT_THAT(bad.summary.stopped, HasSubstr("malformed zstd chunk"));

  McapSummary summary;
  const Status missing = ReadMcap(
      "/nonexistent/bag_0.mcap", [](auto&, auto&) {}, &summary);
  EXPECT_THAT(missing.message(), HasSubstr("/nonexistent/bag_0.mcap: cannot open"));
}

TEST(Mcap, ReadsAFile) {
  testing::ScopedTempDir tmp;
  const std::string path = tmp.path() + "/bag_0.mcap";
  Bytes data;
  PutRecord(&data, 0x06, Chunk(Records(), "zstd"));
  const Bytes file = File(data);
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(file.data()), static_cast<std::streamsize>(file.size()));
  Read read;
  read.status = ReadMcap(
      path,
      [&](const McapChannel& channel, const McapMessage& message) {
        read.topics.push_back(channel.topic);
        read.messages.push_back(message);
      },
      &read.summary);
  ExpectTheThreeMessages(read);
}

// McapWriter's files read back record by record, and cut short they say where they stop.
TEST(Mcap, WritesWhatItReads) {
  testing::ScopedTempDir tmp;
  const std::string path = tmp.path() + "/out_0.mcap";
  {
    McapWriter writer;
    ASSERT_TRUE(writer.Open(path).ok());
    const uint16_t points =
        writer.AddChannel(writer.AddSchema("sensor_msgs/msg/PointCloud2", "x"), "/points");
    const uint16_t image =
        writer.AddChannel(writer.AddSchema("sensor_msgs/msg/Image", "y"), "/image");
    writer.Write(points, 10, {1, 2, 3});
    writer.Write(image, 11, std::vector<uint8_t>(70000, 7));  // larger than any read buffer
    writer.Write(points, 12, {4});
    ASSERT_TRUE(writer.Close().ok());
    EXPECT_EQ(writer.messages_written(), 3u);
  }
  Read read;
  auto visit = [&](const McapChannel& channel, const McapMessage& message) {
    read.topics.push_back(channel.topic + " " + channel.schema_name + " " +
                          channel.message_encoding);
    read.messages.push_back(message);
  };
  read.status = ReadMcap(path, visit, &read.summary);
  ASSERT_TRUE(read.status.ok()) << read.status.message();
  EXPECT_EQ(read.summary.profile, "ros2");
  EXPECT_TRUE(read.summary.stopped.empty()) << read.summary.stopped;
  ASSERT_EQ(read.messages.size(), 3u);
  EXPECT_EQ(read.topics[0], "/points sensor_msgs/msg/PointCloud2 cdr");
  EXPECT_EQ(read.topics[1], "/image sensor_msgs/msg/Image cdr");
  EXPECT_EQ(read.messages[1].data.size(), 70000u);
  EXPECT_EQ(read.messages[2].sequence, 1u);  // counted per channel
  EXPECT_EQ(read.messages[2].log_time_ns, 12u);

  std::filesystem::resize_file(path, std::filesystem::file_size(path) - 60);
  read = Read();
  read.status = ReadMcap(path, visit, &read.summary);
  ASSERT_TRUE(read.status.ok());
  EXPECT_EQ(read.messages.size(), 2u);
  EXPECT_THAT(read.summary.stopped, HasSubstr("truncated"));
}

// The fuzzers' seed bag (written by a separate script from the specification): an Image outside
// chunks and a PointCloud2 inside one, both decoded.
TEST(Mcap, ReadsTheSeedBagAndDecodesItsMessages) {
  const std::string path = std::string(STCALIB_FUZZ_REGRESSIONS_DIR) + "/mcap/image_and_cloud.mcap";
  std::vector<RosImage> images;
  std::vector<CloudPoints> clouds;
  McapSummary summary;
  const Status status = ReadMcap(
      path,
      [&](const McapChannel& channel, const McapMessage& message) {
        if (channel.schema_name == "sensor_msgs/msg/Image") {
          images.emplace_back();
          EXPECT_TRUE(DecodeImage(message.data, &images.back()).ok());
        } else if (channel.schema_name == "sensor_msgs/msg/PointCloud2") {
          RosPointCloud cloud;
          ASSERT_TRUE(DecodePointCloud2(message.data, &cloud).ok());
          clouds.emplace_back();
          EXPECT_TRUE(ExtractCloudPoints(cloud, &clouds.back()).ok());
        }
      },
      &summary);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(summary.stopped, "");
  ASSERT_EQ(images.size(), 1u);
  EXPECT_EQ(images[0].width, 2u);
  EXPECT_EQ(images[0].encoding, "rgb8");
  EXPECT_EQ(images[0].data[11], 11);
  ASSERT_EQ(clouds.size(), 1u);
  ASSERT_EQ(clouds[0].points.size(), 2u);
  EXPECT_EQ(clouds[0].points[1], Eigen::Vector3d(-1.0, 0.5, 9.0));
  EXPECT_EQ(clouds[0].time_field, "t");
  EXPECT_NEAR(clouds[0].time_s[1], 2e-6, 1e-15);
  EXPECT_EQ(clouds[0].ring, (std::vector<uint16_t>{5, 6}));
}

// A rosbag2 SQLite file as rosbag2's default storage plugin lays it out.
void WriteDb3(const std::string& path) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  const char* sql =
      "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
      "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
      "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, "
      "timestamp INTEGER NOT NULL, data BLOB NOT NULL);"
      "INSERT INTO topics VALUES(1, '/camera/image_raw', 'sensor_msgs/msg/Image', 'cdr', '');"
      "INSERT INTO topics VALUES(2, '/lidar/points', 'sensor_msgs/msg/PointCloud2', 'cdr', '');"
      "INSERT INTO topics VALUES(3, '/imu', 'sensor_msgs/msg/Imu', 'cdr', '');"
      "INSERT INTO messages VALUES(1, 2, 2000, x'0405');"
      "INSERT INTO messages VALUES(2, 1, 1000, x'010203');"
      "INSERT INTO messages VALUES(3, 1, 3000, x'');";
  ASSERT_EQ(sqlite3_exec(db, sql, nullptr, nullptr, nullptr), SQLITE_OK) << sqlite3_errmsg(db);
  sqlite3_close(db);
}

struct BagRead {
  Status status = Status::Ok();
  BagSummary summary;
  std::vector<std::string> topics;
  std::vector<int64_t> times;
  std::vector<Bytes> data;
};
BagRead ReadBag(const std::string& folder) {
  BagRead read;
  read.status = ReadRosbag2(
      folder,
      [&](const BagMessage& message) {
        read.topics.push_back(message.topic->name + " " + message.topic->type);
        read.times.push_back(message.log_time_ns);
        read.data.push_back(message.data);
      },
      &read.summary);
  return read;
}

TEST(Rosbag2, ReadsSqliteAndMcapFolders) {
  testing::ScopedTempDir tmp;
  const std::string sqlite_bag = tmp.path() + "/sqlite_bag";
  std::filesystem::create_directories(sqlite_bag);
  WriteDb3(sqlite_bag + "/sqlite_bag_0.db3");
  std::ofstream(sqlite_bag + "/metadata.yaml")
      << "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: sqlite3\n"
         "  relative_file_paths:\n    - sqlite_bag_0.db3\n  duration:\n    nanoseconds: 2000\n";
  const BagRead db3 = ReadBag(sqlite_bag);
  ASSERT_TRUE(db3.status.ok()) << db3.status.message();
  EXPECT_EQ(db3.summary.files, std::vector<std::string>{sqlite_bag + "/sqlite_bag_0.db3"});
  EXPECT_EQ(db3.times, (std::vector<int64_t>{1000, 2000, 3000}));  // by timestamp
  EXPECT_EQ(db3.topics[1], "/lidar/points sensor_msgs/msg/PointCloud2");
  EXPECT_EQ(db3.data[0], (Bytes{1, 2, 3}));
  EXPECT_EQ(db3.summary.topics.size(), 3u);
  EXPECT_EQ(db3.summary.message_count.at("/camera/image_raw"), 2u);
  EXPECT_THAT(ListBagTopics(db3.summary), HasSubstr("  /imu  [sensor_msgs/msg/Imu], 0 messages"));

  const std::string mcap_bag = tmp.path() + "/mcap_bag";  // no metadata.yaml: found by name
  std::filesystem::create_directories(mcap_bag);
  Bytes data;
  PutRecord(&data, 0x06, Chunk(Records(), "zstd"));
  const Bytes file = File(data);
  std::ofstream(mcap_bag + "/mcap_bag_0.mcap", std::ios::binary)
      .write(reinterpret_cast<const char*>(file.data()), static_cast<std::streamsize>(file.size()));
  const BagRead mcap = ReadBag(mcap_bag);
  ASSERT_TRUE(mcap.status.ok()) << mcap.status.message();
  EXPECT_EQ(mcap.times, (std::vector<int64_t>{5000, 6000, 7000}));
  EXPECT_EQ(mcap.topics[0], "/camera/image_raw sensor_msgs/msg/Image");
  EXPECT_EQ(mcap.summary.message_count.at("/lidar/points"), 1u);
}

TEST(Rosbag2, BadBagsAreNamed) {
  testing::ScopedTempDir tmp;
  EXPECT_THAT(ReadBag(tmp.path() + "/none").status.message(), HasSubstr("/none: not a folder"));
  EXPECT_THAT(ReadBag(tmp.path()).status.message(), HasSubstr(": no storage file"));
  const std::string listed = tmp.path() + "/listed";
  std::filesystem::create_directories(listed);
  std::ofstream(listed + "/metadata.yaml") << "  relative_file_paths:\n    - gone_0.mcap\n";
  EXPECT_THAT(ReadBag(listed).status.message(),
              HasSubstr("gone_0.mcap: listed in metadata.yaml but missing"));
  const std::string not_sqlite = tmp.path() + "/not_sqlite";
  std::filesystem::create_directories(not_sqlite);
  std::ofstream(not_sqlite + "/x_0.db3") << "this is not a database, just text";
  EXPECT_THAT(ReadBag(not_sqlite).status.message(), HasSubstr("x_0.db3: "));
  const std::string no_tables = tmp.path() + "/no_tables";
  std::filesystem::create_directories(no_tables);
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open((no_tables + "/y_0.db3").c_str(), &db), SQLITE_OK);
  sqlite3_exec(db, "CREATE TABLE other(a INTEGER);", nullptr, nullptr, nullptr);
  sqlite3_close(db);
  EXPECT_THAT(ReadBag(no_tables).status.message(), HasSubstr("no table `topics`"));
}

}  // namespace
}  // namespace stcalib
