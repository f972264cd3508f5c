// ROS 2 messages in CDR: bytes written here field by field from the OMG CDR rules (little and
// big endian, primitives aligned to their size after the 4-byte encapsulation header) and the
// sensor_msgs message definitions, decoded by core/io/ros_messages.h.

#include "core/io/ros_messages.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

namespace stcalib {
namespace {

using ::testing::HasSubstr;

class CdrWriter {
 public:
  explicit CdrWriter(bool little = true) : little_(little) {
    bytes_ = {0x00, static_cast<uint8_t>(little ? 0x01 : 0x00), 0x00, 0x00};
  }
  template <typename T>
  CdrWriter& Put(T value) {
    while ((bytes_.size() - 4) % sizeof(T) != 0) bytes_.push_back(0xee);  // padding
    uint8_t raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    for (size_t k = 0; k < sizeof(T); ++k) bytes_.push_back(raw[little_ ? k : sizeof(T) - 1 - k]);
    return *this;
  }
  CdrWriter& String(const std::string& s) {
    Put<uint32_t>(static_cast<uint32_t>(s.size() + 1));
    bytes_.insert(bytes_.end(), s.begin(), s.end());
    bytes_.push_back(0);
    return *this;
  }
  CdrWriter& Bytes(const std::vector<uint8_t>& b) {
    Put<uint32_t>(static_cast<uint32_t>(b.size()));
    bytes_.insert(bytes_.end(), b.begin(), b.end());
    return *this;
  }
  CdrWriter& Header(int32_t sec, uint32_t nanosec, const std::string& frame) {
    return Put(sec).Put(nanosec).String(frame);
  }
  const std::vector<uint8_t>& bytes() const { return bytes_; }

 private:
  bool little_;
  std::vector<uint8_t> bytes_;
};

TEST(RosMessages, DecodesImagesInEveryEncodingAndEndianness) {
  // 2 × 2 rgb8 with a padded step of 8 bytes per row.
  const std::vector<uint8_t> rgb = {10, 20, 30, 40, 50, 60, 0, 0, 70, 80, 90, 1, 2, 3, 0, 0};
  for (bool little : {true, false}) {
    CdrWriter w(little);
    w.Header(1317046200, 123456789, "camera").Put<uint32_t>(2).Put<uint32_t>(2);
    w.String("rgb8").Put<uint8_t>(0).Put<uint32_t>(8).Bytes(rgb);
    RosImage image;
    ASSERT_TRUE(DecodeImage(w.bytes(), &image).ok());
    EXPECT_EQ(image.stamp_ns, 1317046200123456789);
    EXPECT_EQ(image.frame_id, "camera");
    EXPECT_EQ(image.encoding, "rgb8");
    cv::Mat bgr;
    ASSERT_TRUE(ImageToBgr(image, &bgr).ok());
    ASSERT_EQ(bgr.type(), CV_8UC3);
    EXPECT_EQ(bgr.at<cv::Vec3b>(0, 1), cv::Vec3b(60, 50, 40));
    EXPECT_EQ(bgr.at<cv::Vec3b>(1, 0), cv::Vec3b(90, 80, 70));
  }
  // mono16, big endian pixels: 0x1234 -> 0x12 after the 1/256 scale.
  CdrWriter w;
  w.Header(5, 0, "ir").Put<uint32_t>(1).Put<uint32_t>(1).String("mono16");
  w.Put<uint8_t>(1).Put<uint32_t>(2).Bytes({0x12, 0x34});
  RosImage image;
  ASSERT_TRUE(DecodeImage(w.bytes(), &image).ok());
  cv::Mat bgr;
  ASSERT_TRUE(ImageToBgr(image, &bgr).ok());
  EXPECT_EQ(bgr.at<cv::Vec3b>(0, 0), cv::Vec3b(0x12, 0x12, 0x12));

  RosImage empty = image;
  empty.width = 0;
  EXPECT_THAT(ImageToBgr(empty, &bgr).message(), HasSubstr("0 × 1 pixels is not an image size"));
  image.encoding = "bayer_rggb8";
  EXPECT_THAT(ImageToBgr(image, &bgr).message(), HasSubstr("\"bayer_rggb8\" is not supported"));
  std::vector<uint8_t> cut = w.bytes();
  cut.resize(cut.size() - 1);
  EXPECT_THAT(DecodeImage(cut, &image).message(), HasSubstr("sensor_msgs/msg/Image: the CDR"));
}

TEST(RosMessages, DecodesCompressedImagesAndCameraInfo) {
  cv::Mat picture(3, 4, CV_8UC3, cv::Scalar(10, 20, 30));
  picture.at<cv::Vec3b>(1, 2) = cv::Vec3b(200, 100, 50);
  std::vector<uint8_t> png;
  ASSERT_TRUE(cv::imencode(".png", picture, png));
  CdrWriter w;
  w.Header(7, 8, "camera").String("png").Bytes(png);
  int64_t stamp_ns = 0;
  cv::Mat bgr;
  ASSERT_TRUE(DecodeCompressedImage(w.bytes(), &stamp_ns, &bgr).ok());
  EXPECT_EQ(stamp_ns, 7000000008);
  ASSERT_EQ(bgr.size(), picture.size());
  EXPECT_EQ(bgr.at<cv::Vec3b>(1, 2), cv::Vec3b(200, 100, 50));
  CdrWriter junk;
  junk.Header(7, 8, "camera").String("jpeg").Bytes({1, 2, 3});
  EXPECT_THAT(DecodeCompressedImage(junk.bytes(), &stamp_ns, &bgr).message(),
              HasSubstr("CompressedImage: its 3 bytes (format \"jpeg\") do not decode"));

  // CameraInfo: the doubles after the distortion model's string are aligned to 8 bytes.
  for (bool little : {true, false}) {
    CdrWriter c(little);
    c.Header(1, 2, "cam").Put<uint32_t>(375).Put<uint32_t>(1242).String("plumb_bob");
    c.Put<uint32_t>(5);
    for (double d : {-0.3, 0.1, 0.001, -0.002, 0.0}) c.Put(d);
    for (double k : {721.5, 0.0, 609.6, 0.0, 721.5, 172.9, 0.0, 0.0, 1.0}) c.Put(k);
    for (double r : {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0}) c.Put(r);
    for (int k = 0; k < 12; ++k) c.Put(k == 0 ? 721.5 : k == 3 ? 44.9 : 0.0);
    c.Put<uint32_t>(0).Put<uint32_t>(0);
    c.Put<uint32_t>(0).Put<uint32_t>(0).Put<uint32_t>(0).Put<uint32_t>(0).Put<uint8_t>(0);
    RosCameraInfo info;
    ASSERT_TRUE(DecodeCameraInfo(c.bytes(), &info).ok());
    EXPECT_EQ(info.width, 1242u);
    EXPECT_EQ(info.distortion_model, "plumb_bob");
    EXPECT_EQ(info.d, (std::vector<double>{-0.3, 0.1, 0.001, -0.002, 0.0}));
    EXPECT_EQ(info.K(0, 2), 609.6);
    EXPECT_EQ(info.K(1, 2), 172.9);
    EXPECT_EQ(info.R, Eigen::Matrix3d::Identity());
    EXPECT_EQ(info.P(0, 3), 44.9);
    std::vector<uint8_t> cut = c.bytes();
    cut.resize(cut.size() - 2);
    EXPECT_THAT(DecodeCameraInfo(cut, &info).message(), HasSubstr("CameraInfo: the CDR bytes"));
  }
}

TEST(RosMessages, DecodesImuAndOdometry) {
  for (bool little : {true, false}) {
    CdrWriter imu(little);
    imu.Header(3, 4, "imu_link");
    for (double q : {0.0, 0.0, 0.7071067811865476, 0.7071067811865476}) imu.Put(q);  // x y z w
    for (int k = 0; k < 9; ++k) imu.Put(0.01);
    imu.Put(0.1).Put(-0.2).Put(0.3);
    for (int k = 0; k < 9; ++k) imu.Put(0.01);
    imu.Put(0.5).Put(0.0).Put(9.81);
    for (int k = 0; k < 9; ++k) imu.Put(0.01);
    RosImu decoded;
    ASSERT_TRUE(DecodeImu(imu.bytes(), &decoded).ok());
    EXPECT_EQ(decoded.stamp_ns, 3000000004);
    EXPECT_NEAR(decoded.orientation.toRotationMatrix()(1, 0), 1.0, 1e-12);  // 90° about z
    EXPECT_EQ(decoded.angular_velocity_rad_s, Eigen::Vector3d(0.1, -0.2, 0.3));
    EXPECT_EQ(decoded.linear_acceleration_m_s2, Eigen::Vector3d(0.5, 0.0, 9.81));
    std::vector<uint8_t> cut = imu.bytes();
    cut.resize(cut.size() - 8);
    EXPECT_THAT(DecodeImu(cut, &decoded).message(), HasSubstr("sensor_msgs/msg/Imu: the CDR"));

    CdrWriter odometry(little);
    odometry.Header(5, 6, "odom").String("base_link");
    odometry.Put(1.0).Put(2.0).Put(3.0);
    for (double q : {0.0, 0.0, 0.0, 1.0}) odometry.Put(q);
    for (int k = 0; k < 36; ++k) odometry.Put(0.0);
    odometry.Put(8.0).Put(0.1).Put(0.0).Put(0.0).Put(0.0).Put(0.05);
    for (int k = 0; k < 36; ++k) odometry.Put(0.0);
    RosOdometry o;
    ASSERT_TRUE(DecodeOdometry(odometry.bytes(), &o).ok());
    EXPECT_EQ(o.child_frame_id, "base_link");
    EXPECT_EQ(o.position_m, Eigen::Vector3d(1, 2, 3));
    EXPECT_EQ(o.linear_m_s, Eigen::Vector3d(8.0, 0.1, 0.0));
    EXPECT_EQ(o.angular_rad_s, Eigen::Vector3d(0, 0, 0.05));
  }
}

struct Field {
  std::string name;
  uint32_t offset;
  uint8_t datatype;
};
// A PointCloud2 of `points` rows of `point_step` bytes laid out by `fill`.
std::vector<uint8_t> Cloud(const std::vector<Field>& fields, uint32_t point_step,
                           const std::vector<std::vector<uint8_t>>& points, bool little = true) {
  CdrWriter w(little);
  w.Header(100, 500000000, "lidar").Put<uint32_t>(1).Put<uint32_t>(points.size());
  w.Put<uint32_t>(fields.size());
  for (const Field& f : fields) w.String(f.name).Put(f.offset).Put(f.datatype).Put<uint32_t>(1);
  std::vector<uint8_t> data;
  for (const auto& p : points) data.insert(data.end(), p.begin(), p.end());
  w.Put<uint8_t>(little ? 0 : 1).Put(point_step).Put<uint32_t>(point_step * points.size());
  w.Bytes(data).Put<uint8_t>(1);
  return w.bytes();
}
template <typename T>
void Place(std::vector<uint8_t>* point, uint32_t offset, T value, bool little = true) {
  uint8_t raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  for (size_t k = 0; k < sizeof(T); ++k) (*point)[offset + k] = raw[little ? k : sizeof(T) - 1 - k];
}

// The three drivers' layouts: Velodyne (float32 x y z intensity, uint16 ring, float32 time in s
// from the sweep's start), Ouster (float32 x y z intensity, uint32 t in ns, uint16 ring) and
// Hesai (float32 x y z intensity, float64 absolute timestamp, uint16 ring).
TEST(RosMessages, ReadsPointsOfEveryDriversLayout) {
  {
    const std::vector<Field> velodyne = {{"x", 0, 7},          {"y", 4, 7},     {"z", 8, 7},
                                         {"intensity", 12, 7}, {"ring", 16, 4}, {"time", 18, 7}};
    std::vector<uint8_t> p(22, 0), q(22, 0);
    Place(&p, 0, 1.5f), Place(&p, 4, -2.0f), Place(&p, 8, 0.25f), Place(&p, 12, 40.0f);
    Place<uint16_t>(&p, 16, 31), Place(&p, 18, 0.05f);
    Place(&q, 0, std::nanf("")), Place(&q, 4, 1.0f), Place(&q, 8, 1.0f);  // a no-return
    RosPointCloud cloud;
    ASSERT_TRUE(DecodePointCloud2(Cloud(velodyne, 22, {p, q}), &cloud).ok());
    EXPECT_EQ(cloud.stamp_ns, 100500000000);
    CloudPoints points;
    ASSERT_TRUE(ExtractCloudPoints(cloud, &points).ok());
    ASSERT_EQ(points.points.size(), 1u);
    EXPECT_EQ(points.points[0], Eigen::Vector3d(1.5, -2.0, 0.25));
    EXPECT_EQ(points.intensity, std::vector<float>{40.0f});
    EXPECT_EQ(points.ring, std::vector<uint16_t>{31});
    EXPECT_EQ(points.time_field, "time");
    EXPECT_NEAR(points.time_s[0], 0.05, 1e-7);
  }
  {
    const std::vector<Field> ouster = {{"x", 0, 7},          {"y", 4, 7},  {"z", 8, 7},
                                       {"intensity", 16, 7}, {"t", 20, 6}, {"ring", 26, 4}};
    for (bool little : {true, false}) {
      std::vector<uint8_t> p(48, 0);
      Place(&p, 0, 3.0f, little), Place(&p, 4, 4.0f, little), Place(&p, 8, -1.0f, little);
      Place<uint32_t>(&p, 20, 25000000, little), Place<uint16_t>(&p, 26, 63, little);
      RosPointCloud cloud;
      ASSERT_TRUE(DecodePointCloud2(Cloud(ouster, 48, {p}, little), &cloud).ok());
      EXPECT_EQ(cloud.big_endian, !little);
      CloudPoints points;
      ASSERT_TRUE(ExtractCloudPoints(cloud, &points).ok());
      ASSERT_EQ(points.points.size(), 1u);
      EXPECT_EQ(points.points[0], Eigen::Vector3d(3, 4, -1));
      EXPECT_EQ(points.time_field, "t");
      EXPECT_NEAR(points.time_s[0], 0.025, 1e-12);  // integer ns
      EXPECT_EQ(points.ring, std::vector<uint16_t>{63});
    }
  }
  {
    const std::vector<Field> hesai = {{"x", 0, 7},          {"y", 4, 7},          {"z", 8, 7},
                                      {"intensity", 12, 7}, {"timestamp", 16, 8}, {"ring", 24, 4}};
    std::vector<uint8_t> p(32, 0);
    Place(&p, 0, 1.0f), Place(&p, 4, 1.0f), Place(&p, 8, 1.0f);
    Place(&p, 16, 100.5 + 0.0125 + 1.7e9);  // absolute seconds
    std::vector<uint8_t> bytes = Cloud(hesai, 32, {p});
    RosPointCloud cloud;
    ASSERT_TRUE(DecodePointCloud2(bytes, &cloud).ok());
    cloud.stamp_ns += 1700000000000000000;  // the cloud stamped on the same epoch clock
    CloudPoints points;
    ASSERT_TRUE(ExtractCloudPoints(cloud, &points).ok());
    EXPECT_NEAR(points.time_s[0], 0.0125, 1e-6);
  }
}

TEST(RosMessages, BadCloudsAreNamed) {
  std::vector<uint8_t> p(12, 0);
  RosPointCloud cloud;
  ASSERT_TRUE(DecodePointCloud2(Cloud({{"x", 0, 7}, {"y", 4, 7}}, 12, {p}), &cloud).ok());
  CloudPoints points;
  EXPECT_THAT(ExtractCloudPoints(cloud, &points).message(), HasSubstr("no field \"z\""));
  ASSERT_TRUE(
      DecodePointCloud2(Cloud({{"x", 0, 7}, {"y", 4, 7}, {"z", 10, 7}}, 12, {p}), &cloud).ok());
  EXPECT_THAT(ExtractCloudPoints(cloud, &points).message(),
              HasSubstr("field \"z\" (datatype 7 at offset 10) does not fit a point of 12 bytes"));
  ASSERT_TRUE(
      DecodePointCloud2(Cloud({{"x", 0, 7}, {"y", 4, 7}, {"z", 8, 7}}, 12, {p}), &cloud).ok());
  cloud.width = 2;  // claims two points, holds one
  EXPECT_THAT(ExtractCloudPoints(cloud, &points).message(), HasSubstr("do not fit its 12 data"));
  std::vector<uint8_t> q(14, 0);
  Place<float>(&q, 0, 5.0f);  // a return (a point at the origin is a no-return, left out)
  Place<int16_t>(&q, 12, -13);
  ASSERT_TRUE(DecodePointCloud2(
                  Cloud({{"x", 0, 7}, {"y", 4, 7}, {"z", 8, 7}, {"ring", 12, 3}}, 14, {q}), &cloud)
                  .ok());
  EXPECT_THAT(ExtractCloudPoints(cloud, &points).message(), HasSubstr("\"ring\" holds -13"));
  std::vector<uint8_t> cut = Cloud({{"x", 0, 7}, {"y", 4, 7}, {"z", 8, 7}}, 12, {p});
  cut.resize(cut.size() - 3);
  EXPECT_THAT(DecodePointCloud2(cut, &cloud).message(),
              HasSubstr("sensor_msgs/msg/PointCloud2: the CDR bytes end"));
}

}  // namespace
}  // namespace stcalib

namespace stcalib {
namespace {

// The encoders write what the decoders (checked above against hand-built CDR) read back.
TEST(RosMessages, EncodersWriteWhatTheDecodersRead) {
  RosImage image;
  image.stamp_ns = 1317042651158069617;
  image.frame_id = "camera";
  image.height = 2;
  image.width = 3;
  image.encoding = "bgr8";
  image.step = 9;
  image.data = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18};
  RosImage image_back;
  ASSERT_TRUE(DecodeImage(EncodeImage(image), &image_back).ok());
  EXPECT_EQ(image_back.stamp_ns, image.stamp_ns);
  EXPECT_EQ(image_back.frame_id, "camera");
  EXPECT_EQ(image_back.encoding, "bgr8");
  EXPECT_EQ(image_back.step, 9u);
  EXPECT_EQ(image_back.data, image.data);

  RosCameraInfo info;
  info.stamp_ns = 42;
  info.width = 1242;
  info.height = 375;
  info.distortion_model = "equidistant";
  info.d = {0.1, -0.02, 0.003, -0.0004};
  info.K << 700, 0, 600, 0, 701, 180, 0, 0, 1;
  info.R = Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitY()).toRotationMatrix();
  info.P << 700, 0, 600, 44.8, 0, 701, 180, 0.2, 0, 0, 1, 0.003;
  RosCameraInfo info_back;
  ASSERT_TRUE(DecodeCameraInfo(EncodeCameraInfo(info), &info_back).ok());
  EXPECT_EQ(info_back.distortion_model, "equidistant");
  EXPECT_EQ(info_back.d, info.d);
  EXPECT_EQ(info_back.K, info.K);
  EXPECT_EQ(info_back.R, info.R);
  EXPECT_EQ(info_back.P, info.P);

  RosOdometry odometry;
  odometry.stamp_ns = -1500000000;  // before the epoch: sec −2, nanosec 5e8
  odometry.frame_id = "world";
  odometry.child_frame_id = "imu";
  odometry.position_m = Eigen::Vector3d(1, -2, 3);
  odometry.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()));
  odometry.linear_m_s = Eigen::Vector3d(8, 0.1, 0);
  odometry.angular_rad_s = Eigen::Vector3d(0, 0, 0.05);
  RosOdometry odometry_back;
  ASSERT_TRUE(DecodeOdometry(EncodeOdometry(odometry), &odometry_back).ok());
  EXPECT_EQ(odometry_back.stamp_ns, odometry.stamp_ns);
  EXPECT_EQ(odometry_back.child_frame_id, "imu");
  EXPECT_EQ(odometry_back.position_m, odometry.position_m);
  EXPECT_EQ(odometry_back.orientation.coeffs(), odometry.orientation.coeffs());
  EXPECT_EQ(odometry_back.linear_m_s, odometry.linear_m_s);
  EXPECT_EQ(odometry_back.angular_rad_s, odometry.angular_rad_s);

  RosTransform a, b;
  a.stamp_ns = 7;
  a.frame_id = "camera";
  a.child_frame_id = "lidar";
  a.T_parent_child.linear() =
      Eigen::AngleAxisd(1.2, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  a.T_parent_child.translation() = Eigen::Vector3d(0.27, -0.08, -0.06);
  b.frame_id = "lidar";
  b.child_frame_id = "imu";
  std::vector<RosTransform> back;
  ASSERT_TRUE(DecodeTfMessage(EncodeTfMessage({a, b}), &back).ok());
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[0].frame_id, "camera");
  EXPECT_EQ(back[0].child_frame_id, "lidar");
  EXPECT_TRUE(back[0].T_parent_child.isApprox(a.T_parent_child, 1e-15));
  EXPECT_EQ(back[1].child_frame_id, "imu");
  std::vector<uint8_t> cut = EncodeTfMessage({a, b});
  cut.resize(cut.size() - 10);
  EXPECT_THAT(DecodeTfMessage(cut, &back).message(), HasSubstr("tf2_msgs/msg/TFMessage"));
  EXPECT_TRUE(back.empty());  // nothing half-read (the fuzzer's find: a NaN translation)
  RosTransform broken = a;
  broken.T_parent_child.translation().x() = std::nan("");
  EXPECT_THAT(DecodeTfMessage(EncodeTfMessage({broken}), &back).message(),
              HasSubstr("camera <- lidar is not a rigid transform"));

  RosPointCloud cloud;
  cloud.stamp_ns = 5;
  cloud.frame_id = "lidar";
  cloud.height = 1;
  cloud.width = 2;
  cloud.fields = {{"x", 0, 7, 1}, {"y", 4, 7, 1}, {"z", 8, 7, 1}, {"t", 12, 6, 1}};
  cloud.point_step = 16;
  cloud.row_step = 32;
  cloud.data.assign(32, 0);
  const float p0[3] = {1, 2, 3}, p1[3] = {-4, 5, 0.5f};
  const uint32_t t0 = 1000, t1 = 50000000;
  std::memcpy(cloud.data.data(), p0, 12);
  std::memcpy(cloud.data.data() + 12, &t0, 4);
  std::memcpy(cloud.data.data() + 16, p1, 12);
  std::memcpy(cloud.data.data() + 28, &t1, 4);
  RosPointCloud cloud_back;
  ASSERT_TRUE(DecodePointCloud2(EncodePointCloud2(cloud), &cloud_back).ok());
  CloudPoints points;
  ASSERT_TRUE(ExtractCloudPoints(cloud_back, &points).ok());
  ASSERT_EQ(points.points.size(), 2u);
  EXPECT_EQ(points.points[1], Eigen::Vector3d(-4, 5, 0.5));
  EXPECT_EQ(points.time_field, "t");
  EXPECT_DOUBLE_EQ(points.time_s[1], 0.05);
  for (const char* type :
       {"sensor_msgs/msg/Image", "sensor_msgs/msg/CameraInfo", "sensor_msgs/msg/PointCloud2",
        "nav_msgs/msg/Odometry", "tf2_msgs/msg/TFMessage"}) {
    EXPECT_THAT(Ros2MsgDefinition(type), HasSubstr("MSG: ")) << type;
  }
}

}  // namespace
}  // namespace stcalib
