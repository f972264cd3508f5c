#include "core/io/ros_messages.h"

#include <cmath>
#include <cstring>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace stcalib {
namespace {

// Reads CDR fields in order; the first failure sticks, and every later read fails too.
class Cdr {
 public:
  explicit Cdr(const std::vector<uint8_t>& bytes) : bytes_(bytes) {
    // Encapsulation: 0x00 0x00 big endian CDR, 0x00 0x01 little endian; two option bytes.
    ok_ = bytes.size() >= 4 && bytes[0] == 0 && (bytes[1] == 0 || bytes[1] == 1);
    little_ = ok_ && bytes[1] == 1;
    at_ = 4;
  }
  bool ok() const { return ok_; }
  void Fail() { ok_ = false; }  ///< a length the bytes cannot hold
  template <typename T>
  T Get() {
    T value{};
    if (!ok_) return value;
    at_ = 4 + ((at_ - 4 + sizeof(T) - 1) / sizeof(T)) * sizeof(T);  // align to the size
    if (at_ > bytes_.size() || sizeof(T) > bytes_.size() - at_) {
      ok_ = false;
      return value;
    }
    uint8_t raw[sizeof(T)];
    for (size_t k = 0; k < sizeof(T); ++k) {
      raw[k] = bytes_[at_ + (little_ ? k : sizeof(T) - 1 - k)];
    }
    std::memcpy(&value, raw, sizeof(T));
    at_ += sizeof(T);
    return value;
  }
  std::string String() {
    const uint32_t n = Get<uint32_t>();  // with the terminating NUL
    if (!ok_ || n > bytes_.size() - at_) {
      ok_ = false;
      return "";
    }
    std::string s(reinterpret_cast<const char*>(bytes_.data() + at_), n > 0 ? n - 1 : 0);
    at_ += n;
    return s;
  }
  std::vector<uint8_t> Bytes() {
    const uint32_t n = Get<uint32_t>();
    if (!ok_ || n > bytes_.size() - at_) {
      ok_ = false;
      return {};
    }
    std::vector<uint8_t> out(bytes_.begin() + at_, bytes_.begin() + at_ + n);
    at_ += n;
    return out;
  }
  // std_msgs/msg/Header: builtin_interfaces/Time (int32 sec, uint32 nanosec), frame_id.
  void Header(int64_t* stamp_ns, std::string* frame_id) {
    const int32_t sec = Get<int32_t>();
    const uint32_t nanosec = Get<uint32_t>();
    *stamp_ns = int64_t{sec} * 1000000000 + nanosec;
    *frame_id = String();
  }

 private:
  const std::vector<uint8_t>& bytes_;
  bool ok_ = false, little_ = true;
  size_t at_ = 0;
};

Status Truncated(const std::string& type) {
  return Status::Error(type + ": the CDR bytes end before the message does (or bad encapsulation)");
}

// A message of `type`, reset and then filled by `read` field by field from the CDR bytes; the
// first read past the end (or a bad encapsulation header) makes it an error naming the type.
template <typename Message, typename Read>
Status Decode(const std::vector<uint8_t>& cdr, const std::string& type, Message* message,
              Read read) {
  Cdr in(cdr);
  *message = Message();
  read(&in, message);
  return in.ok() ? Status::Ok() : Truncated(type);
}

size_t DatatypeBytes(uint8_t datatype) {
  switch (datatype) {
    case 1:
    case 2:
      return 1;
    case 3:
    case 4:
      return 2;
    case 5:
    case 6:
    case 7:
      return 4;
    case 8:
      return 8;
    default:
      return 0;
  }
}

// One field's value of the point at `p` as a double; integers as they are.
double FieldValue(const uint8_t* p, uint8_t datatype, bool big_endian) {
  uint8_t raw[8];
  const size_t n = DatatypeBytes(datatype);
  for (size_t k = 0; k < n; ++k) raw[k] = p[big_endian ? n - 1 - k : k];
  auto as = [&](auto value) {
    std::memcpy(&value, raw, sizeof(value));
    return static_cast<double>(value);
  };
  switch (datatype) {
    case 1:
      return as(int8_t{});
    case 2:
      return as(uint8_t{});
    case 3:
      return as(int16_t{});
    case 4:
      return as(uint16_t{});
    case 5:
      return as(int32_t{});
    case 6:
      return as(uint32_t{});
    case 7:
      return as(float{});
    default:
      return as(double{});
  }
}

}  // namespace

Status DecodeImage(const std::vector<uint8_t>& cdr, RosImage* image) {
  STCALIB_RETURN_IF_ERROR(Decode(cdr, "sensor_msgs/msg/Image", image, [](Cdr* in, RosImage* m) {
    in->Header(&m->stamp_ns, &m->frame_id);
    m->height = in->Get<uint32_t>();
    m->width = in->Get<uint32_t>();
    m->encoding = in->String();
    m->big_endian = in->Get<uint8_t>() != 0;
    m->step = in->Get<uint32_t>();
    m->data = in->Bytes();
  }));
  if (uint64_t{image->step} * image->height > image->data.size()) {
    return Status::Error("sensor_msgs/msg/Image: " + std::to_string(image->height) + " rows of " +
                         std::to_string(image->step) + " bytes need more than its " +
                         std::to_string(image->data.size()) + " data bytes");
  }
  return Status::Ok();
}

Status ImageToBgr(const RosImage& image, cv::Mat* bgr) {
  constexpr uint32_t kMaxSide = 1 << 16;
  if (image.width == 0 || image.height == 0 || image.width > kMaxSide || image.height > kMaxSide) {
    return Status::Error("sensor_msgs/msg/Image: " + std::to_string(image.width) + " × " +
                         std::to_string(image.height) + " pixels is not an image size");
  }
  const int rows = static_cast<int>(image.height), cols = static_cast<int>(image.width);
  auto view = [&](int type, int channel_bytes) -> Status {
    if (uint64_t{image.width} * channel_bytes > image.step) {
      return Status::Error("sensor_msgs/msg/Image: step " + std::to_string(image.step) +
                           " is shorter than a row of " + image.encoding);
    }
    const cv::Mat m(rows, cols, type, const_cast<uint8_t*>(image.data.data()), image.step);
    if (image.encoding == "bgr8") {
      *bgr = m.clone();
    } else if (image.encoding == "rgb8") {
      cv::cvtColor(m, *bgr, cv::COLOR_RGB2BGR);
    } else if (image.encoding == "mono8") {
      cv::cvtColor(m, *bgr, cv::COLOR_GRAY2BGR);
    } else {  // mono16, in the host's byte order once swapped
      cv::Mat wide = m.clone();
      if (image.big_endian) {
        for (int r = 0; r < rows; ++r) {
          uint16_t* row = wide.ptr<uint16_t>(r);
          for (int c = 0; c < cols; ++c)
            row[c] = static_cast<uint16_t>((row[c] >> 8) | (row[c] << 8));
        }
      }
      cv::Mat narrow;
      wide.convertTo(narrow, CV_8U, 1.0 / 256);
      cv::cvtColor(narrow, *bgr, cv::COLOR_GRAY2BGR);
    }
    return Status::Ok();
  };
  if (image.encoding == "bgr8" || image.encoding == "rgb8") return view(CV_8UC3, 3);
  if (image.encoding == "mono8") return view(CV_8UC1, 1);
  if (image.encoding == "mono16") return view(CV_16UC1, 2);
  return Status::Error("sensor_msgs/msg/Image: encoding \"" + image.encoding +
                       "\" is not supported (rgb8, bgr8, mono8, mono16)");
}

Status DecodeCompressedImage(const std::vector<uint8_t>& cdr, int64_t* stamp_ns, cv::Mat* bgr) {
  Cdr in(cdr);
  std::string frame_id;
  in.Header(stamp_ns, &frame_id);
  const std::string format = in.String();
  const std::vector<uint8_t> data = in.Bytes();
  const std::string type = "sensor_msgs/msg/CompressedImage";
  if (!in.ok()) return Truncated(type);
  cv::Mat decoded;
  try {
    decoded = data.empty() ? cv::Mat() : cv::imdecode(data, cv::IMREAD_COLOR);
  } catch (const cv::Exception& e) {
    decoded = cv::Mat();
  }
  if (decoded.empty()) {
    return Status::Error(type + ": its " + std::to_string(data.size()) + " bytes (format \"" +
                         format + "\") do not decode as an image");
  }
  *bgr = decoded;
  return Status::Ok();
}

Status DecodeCameraInfo(const std::vector<uint8_t>& cdr, RosCameraInfo* info) {
  return Decode(cdr, "sensor_msgs/msg/CameraInfo", info, [&](Cdr* in, RosCameraInfo* m) {
    in->Header(&m->stamp_ns, &m->frame_id);
    m->height = in->Get<uint32_t>();
    m->width = in->Get<uint32_t>();
    m->distortion_model = in->String();
    const uint32_t n = in->Get<uint32_t>();
    if (n > cdr.size() / 8) return in->Fail();
    for (uint32_t k = 0; k < n; ++k) m->d.push_back(in->Get<double>());
    for (int k = 0; k < 9; ++k) m->K(k / 3, k % 3) = in->Get<double>();
    for (int k = 0; k < 9; ++k) m->R(k / 3, k % 3) = in->Get<double>();
    for (int k = 0; k < 12; ++k) m->P(k / 4, k % 4) = in->Get<double>();
    in->Get<uint32_t>();                              // binning_x
    in->Get<uint32_t>();                              // binning_y
    for (int k = 0; k < 4; ++k) in->Get<uint32_t>();  // roi: x_offset, y_offset, height, width
    in->Get<uint8_t>();                               // roi.do_rectify
  });
}

namespace {

Eigen::Vector3d GetVector3(Cdr* in) {
  const double x = in->Get<double>(), y = in->Get<double>(), z = in->Get<double>();
  return Eigen::Vector3d(x, y, z);
}
// geometry_msgs/msg/Quaternion: x, y, z, w.
Eigen::Quaterniond GetQuaternion(Cdr* in) {
  const double x = in->Get<double>(), y = in->Get<double>(), z = in->Get<double>();
  const double w = in->Get<double>();
  return Eigen::Quaterniond(w, x, y, z);
}
void SkipDoubles(Cdr* in, int n) {
  for (int k = 0; k < n; ++k) in->Get<double>();
}

}  // namespace

Status DecodeImu(const std::vector<uint8_t>& cdr, RosImu* imu) {
  return Decode(cdr, "sensor_msgs/msg/Imu", imu, [](Cdr* in, RosImu* m) {
    in->Header(&m->stamp_ns, &m->frame_id);
    m->orientation = GetQuaternion(in);
    SkipDoubles(in, 9);
    m->angular_velocity_rad_s = GetVector3(in);
    SkipDoubles(in, 9);
    m->linear_acceleration_m_s2 = GetVector3(in);
    SkipDoubles(in, 9);
  });
}

Status DecodeOdometry(const std::vector<uint8_t>& cdr, RosOdometry* odometry) {
  return Decode(cdr, "nav_msgs/msg/Odometry", odometry, [](Cdr* in, RosOdometry* m) {
    in->Header(&m->stamp_ns, &m->frame_id);
    m->child_frame_id = in->String();
    m->position_m = GetVector3(in);
    m->orientation = GetQuaternion(in);
    SkipDoubles(in, 36);
    m->linear_m_s = GetVector3(in);
    m->angular_rad_s = GetVector3(in);
    SkipDoubles(in, 36);
  });
}

Status DecodePointCloud2(const std::vector<uint8_t>& cdr, RosPointCloud* cloud) {
  return Decode(cdr, "sensor_msgs/msg/PointCloud2", cloud, [](Cdr* in, RosPointCloud* m) {
    in->Header(&m->stamp_ns, &m->frame_id);
    m->height = in->Get<uint32_t>();
    m->width = in->Get<uint32_t>();
    const uint32_t fields = in->Get<uint32_t>();
    for (uint32_t k = 0; in->ok() && k < fields; ++k) {
      RosPointField f;
      f.name = in->String();
      f.offset = in->Get<uint32_t>();
      f.datatype = in->Get<uint8_t>();
      f.count = in->Get<uint32_t>();
      m->fields.push_back(f);
    }
    m->big_endian = in->Get<uint8_t>() != 0;
    m->point_step = in->Get<uint32_t>();
    m->row_step = in->Get<uint32_t>();
    m->data = in->Bytes();
    m->dense = in->Get<uint8_t>() != 0;
  });
}

Status ExtractCloudPoints(const RosPointCloud& cloud, CloudPoints* out) {
  *out = CloudPoints();
  const std::string type = "sensor_msgs/msg/PointCloud2";
  auto find = [&](const std::string& name) -> const RosPointField* {
    for (const RosPointField& f : cloud.fields) {
      if (f.name == name) return &f;
    }
    return nullptr;
  };
  const RosPointField* xyz[3] = {find("x"), find("y"), find("z")};
  for (int a = 0; a < 3; ++a) {
    if (xyz[a] == nullptr) {
      return Status::Error(type + ": no field \"" + std::string(1, "xyz"[a]) + "\"");
    }
  }
  const RosPointField* intensity = find("intensity");
  const RosPointField* ring = find("ring");
  const RosPointField* time = nullptr;
  for (const char* name : {"time", "t", "timestamp"}) {
    if (time == nullptr && (time = find(name)) != nullptr) out->time_field = name;
  }
  for (const RosPointField* f : {xyz[0], xyz[1], xyz[2], intensity, ring, time}) {
    if (f == nullptr) continue;
    const size_t n = DatatypeBytes(f->datatype);
    if (n == 0 || uint64_t{f->offset} + n > cloud.point_step) {
      return Status::Error(type + ": field \"" + f->name + "\" (datatype " +
                           std::to_string(f->datatype) + " at offset " + std::to_string(f->offset) +
                           ") does not fit a point of " + std::to_string(cloud.point_step) +
                           " bytes");
    }
  }
  const uint64_t count = uint64_t{cloud.width} * cloud.height;
  if (cloud.point_step == 0 || count * cloud.point_step > cloud.data.size() ||
      uint64_t{cloud.row_step} * cloud.height > cloud.data.size() ||
      cloud.row_step < uint64_t{cloud.width} * cloud.point_step) {
    return Status::Error(type + ": " + std::to_string(cloud.height) + " × " +
                         std::to_string(cloud.width) + " points of " +
                         std::to_string(cloud.point_step) + " bytes (rows of " +
                         std::to_string(cloud.row_step) + ") do not fit its " +
                         std::to_string(cloud.data.size()) + " data bytes");
  }
  const double stamp_s = 1e-9 * static_cast<double>(cloud.stamp_ns);
  const bool integer_time = time != nullptr && time->datatype <= 6;
  for (uint32_t r = 0; r < cloud.height; ++r) {
    for (uint32_t c = 0; c < cloud.width; ++c) {
      const uint8_t* p =
          cloud.data.data() + uint64_t{r} * cloud.row_step + uint64_t{c} * cloud.point_step;
      Eigen::Vector3d point;
      for (int a = 0; a < 3; ++a) {
        point[a] = FieldValue(p + xyz[a]->offset, xyz[a]->datatype, cloud.big_endian);
      }
      if (!point.allFinite()) continue;
      out->points.push_back(point);
      if (intensity) {
        out->intensity.push_back(static_cast<float>(
            FieldValue(p + intensity->offset, intensity->datatype, cloud.big_endian)));
      }
      if (ring) {
        const double value = FieldValue(p + ring->offset, ring->datatype, cloud.big_endian);
        if (!(value >= 0 && value <= 65535)) {
          return Status::Error(type + ": field \"ring\" holds " + std::to_string(value) +
                               ", not a ring number");
        }
        out->ring.push_back(static_cast<uint16_t>(value));
      }
      if (time) {
        const double value = FieldValue(p + time->offset, time->datatype, cloud.big_endian);
        double t = integer_time ? 1e-9 * value : value;
        // Absolute stamps (seconds since the epoch, e.g. Hesai's) become relative to the cloud's.
        if (t > 1e8) t -= stamp_s;
        out->time_s.push_back(t);
      }
    }
  }
  return Status::Ok();
}

}  // namespace stcalib
