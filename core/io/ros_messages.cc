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

Status DecodeHeader(const std::vector<uint8_t>& cdr, int64_t* stamp_ns, std::string* frame_id) {
  Cdr in(cdr);
  in.Header(stamp_ns, frame_id);
  return in.ok() ? Status::Ok() : Truncated("std_msgs/msg/Header");
}

Status DecodeImage(const std::vector<uint8_t>& cdr, RosImage* image) {
  STCALIB_RETURN_IF_ERROR(Decode(cdr, kRosImageType, image, [](Cdr* in, RosImage* m) {
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
  const std::string type = kRosCompressedImageType;
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
  return Decode(cdr, kRosCameraInfoType, info, [&](Cdr* in, RosCameraInfo* m) {
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
  return Decode(cdr, kRosImuType, imu, [](Cdr* in, RosImu* m) {
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
  return Decode(cdr, kRosOdometryType, odometry, [](Cdr* in, RosOdometry* m) {
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
  return Decode(cdr, kRosPointCloud2Type, cloud, [](Cdr* in, RosPointCloud* m) {
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
  const std::string type = kRosPointCloud2Type;
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
      if (!point.allFinite() || point.isZero()) continue;  // no return (NaN, or Ouster's zeros)
      out->points.push_back(point);
      if (cloud.height > 1) out->row.push_back(r);
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

Status DecodeTfMessage(const std::vector<uint8_t>& cdr, std::vector<RosTransform>* transforms) {
  std::vector<Eigen::Quaterniond> rotations;
  const Status decoded =
      Decode(cdr, kRosTfMessageType, transforms, [&](Cdr* in, std::vector<RosTransform>* m) {
        const uint32_t n = in->Get<uint32_t>();
        if (n > cdr.size() / 64) return in->Fail();  // each takes more than 64 bytes
        for (uint32_t k = 0; in->ok() && k < n; ++k) {
          RosTransform t;
          in->Header(&t.stamp_ns, &t.frame_id);
          t.child_frame_id = in->String();
          const Eigen::Vector3d translation = GetVector3(in);
          const Eigen::Quaterniond rotation = GetQuaternion(in);
          rotations.push_back(rotation);
          t.T_parent_child.translation() = translation;
          m->push_back(t);
        }
      });
  // Nothing half-read is handed out, and a transform a calibration would start from must be one:
  // finite, with a unit quaternion.
  Status status = decoded;
  for (size_t k = 0; status.ok() && k < transforms->size(); ++k) {
    RosTransform& t = (*transforms)[k];
    const double norm = rotations[k].norm();
    if (!t.T_parent_child.translation().allFinite() || !(std::abs(norm - 1.0) < 1e-3)) {
      status = Status::Error("tf2_msgs/msg/TFMessage: transform " + t.frame_id + " <- " +
                             t.child_frame_id + " is not a rigid transform (quaternion norm " +
                             std::to_string(norm) + ")");
    }
    t.T_parent_child.linear() = rotations[k].normalized().toRotationMatrix();
  }
  if (!status.ok()) transforms->clear();
  return status;
}

namespace {

// Writes little-endian CDR (encapsulation 0x00 0x01), each primitive aligned to its size.
class CdrWriter {
 public:
  CdrWriter() : bytes_{0, 1, 0, 0} {}
  template <typename T>
  CdrWriter& Put(T value) {
    while ((bytes_.size() - 4) % sizeof(T) != 0) bytes_.push_back(0);
    uint8_t raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));  // little-endian hosts only (x86, ARM)
    bytes_.insert(bytes_.end(), raw, raw + sizeof(T));
    return *this;
  }
  CdrWriter& String(const std::string& s) {
    Put(static_cast<uint32_t>(s.size() + 1));
    bytes_.insert(bytes_.end(), s.begin(), s.end());
    bytes_.push_back(0);
    return *this;
  }
  CdrWriter& Bytes(const std::vector<uint8_t>& data) {
    Put(static_cast<uint32_t>(data.size()));
    bytes_.insert(bytes_.end(), data.begin(), data.end());
    return *this;
  }
  CdrWriter& Header(int64_t stamp_ns, const std::string& frame_id) {
    const int64_t sec = stamp_ns >= 0 ? stamp_ns / 1000000000 : (stamp_ns - 999999999) / 1000000000;
    Put(static_cast<int32_t>(sec));
    Put(static_cast<uint32_t>(stamp_ns - sec * 1000000000));
    return String(frame_id);
  }
  CdrWriter& Vector3(const Eigen::Vector3d& v) { return Put(v.x()).Put(v.y()).Put(v.z()); }
  CdrWriter& Quaternion(const Eigen::Quaterniond& q) {
    return Put(q.x()).Put(q.y()).Put(q.z()).Put(q.w());
  }
  CdrWriter& Zeros(int doubles) {
    for (int k = 0; k < doubles; ++k) Put(0.0);
    return *this;
  }
  std::vector<uint8_t> Take() { return std::move(bytes_); }

 private:
  std::vector<uint8_t> bytes_;
};

}  // namespace

std::vector<uint8_t> EncodeImage(const RosImage& m) {
  CdrWriter out;
  out.Header(m.stamp_ns, m.frame_id).Put(m.height).Put(m.width).String(m.encoding);
  out.Put(static_cast<uint8_t>(m.big_endian)).Put(m.step).Bytes(m.data);
  return out.Take();
}

std::vector<uint8_t> EncodeCameraInfo(const RosCameraInfo& m) {
  CdrWriter out;
  out.Header(m.stamp_ns, m.frame_id).Put(m.height).Put(m.width).String(m.distortion_model);
  out.Put(static_cast<uint32_t>(m.d.size()));
  for (double d : m.d) out.Put(d);
  for (int k = 0; k < 9; ++k) out.Put(m.K(k / 3, k % 3));
  for (int k = 0; k < 9; ++k) out.Put(m.R(k / 3, k % 3));
  for (int k = 0; k < 12; ++k) out.Put(m.P(k / 4, k % 4));
  out.Put(uint32_t{0}).Put(uint32_t{0});             // binning
  for (int k = 0; k < 4; ++k) out.Put(uint32_t{0});  // roi
  out.Put(uint8_t{0});                               // roi.do_rectify
  return out.Take();
}

std::vector<uint8_t> EncodePointCloud2(const RosPointCloud& m) {
  CdrWriter out;
  out.Header(m.stamp_ns, m.frame_id).Put(m.height).Put(m.width);
  out.Put(static_cast<uint32_t>(m.fields.size()));
  for (const RosPointField& f : m.fields)
    out.String(f.name).Put(f.offset).Put(f.datatype).Put(f.count);
  out.Put(static_cast<uint8_t>(m.big_endian)).Put(m.point_step).Put(m.row_step).Bytes(m.data);
  out.Put(static_cast<uint8_t>(m.dense));
  return out.Take();
}

std::vector<uint8_t> EncodeOdometry(const RosOdometry& m) {
  CdrWriter out;
  out.Header(m.stamp_ns, m.frame_id).String(m.child_frame_id);
  out.Vector3(m.position_m).Quaternion(m.orientation).Zeros(36);
  out.Vector3(m.linear_m_s).Vector3(m.angular_rad_s).Zeros(36);
  return out.Take();
}

std::vector<uint8_t> EncodeImu(const RosImu& m) {
  CdrWriter out;
  out.Header(m.stamp_ns, m.frame_id).Quaternion(m.orientation).Zeros(9);
  out.Vector3(m.angular_velocity_rad_s).Zeros(9).Vector3(m.linear_acceleration_m_s2).Zeros(9);
  return out.Take();
}

std::vector<uint8_t> EncodeTfMessage(const std::vector<RosTransform>& transforms) {
  CdrWriter out;
  out.Put(static_cast<uint32_t>(transforms.size()));
  for (const RosTransform& t : transforms) {
    out.Header(t.stamp_ns, t.frame_id).String(t.child_frame_id);
    out.Vector3(t.T_parent_child.translation());
    out.Quaternion(Eigen::Quaterniond(t.T_parent_child.linear()));
  }
  return out.Take();
}

std::string Ros2MsgDefinition(const std::string& type) {
  const std::string separator =
      "\n================================================================================\nMSG: ";
  const std::string header = separator +
                             "std_msgs/Header\nbuiltin_interfaces/Time stamp\n"
                             "string frame_id" +
                             separator + "builtin_interfaces/Time\nint32 sec\nuint32 nanosec";
  const std::string vector3 = separator + "geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z";
  const std::string quaternion = separator +
                                 "geometry_msgs/Quaternion\nfloat64 x 0\nfloat64 y 0\n"
                                 "float64 z 0\nfloat64 w 1";
  if (type == kRosImageType) {
    return "std_msgs/Header header\nuint32 height\nuint32 width\nstring encoding\n"
           "uint8 is_bigendian\nuint32 step\nuint8[] data" +
           header;
  }
  if (type == kRosCameraInfoType) {
    return "std_msgs/Header header\nuint32 height\nuint32 width\nstring distortion_model\n"
           "float64[] d\nfloat64[9] k\nfloat64[9] r\nfloat64[12] p\nuint32 binning_x\n"
           "uint32 binning_y\nsensor_msgs/RegionOfInterest roi" +
           header + separator +
           "sensor_msgs/RegionOfInterest\nuint32 x_offset\nuint32 y_offset\nuint32 height\n"
           "uint32 width\nbool do_rectify";
  }
  if (type == kRosPointCloud2Type) {
    return "std_msgs/Header header\nuint32 height\nuint32 width\nsensor_msgs/PointField[] fields\n"
           "bool is_bigendian\nuint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense" +
           header + separator +
           "sensor_msgs/PointField\nuint8 INT8=1\nuint8 UINT8=2\nuint8 INT16=3\nuint8 UINT16=4\n"
           "uint8 INT32=5\nuint8 UINT32=6\nuint8 FLOAT32=7\nuint8 FLOAT64=8\nstring name\n"
           "uint32 offset\nuint8 datatype\nuint32 count";
  }
  if (type == kRosOdometryType) {
    return "std_msgs/Header header\nstring child_frame_id\n"
           "geometry_msgs/PoseWithCovariance pose\ngeometry_msgs/TwistWithCovariance twist" +
           header + separator +
           "geometry_msgs/PoseWithCovariance\ngeometry_msgs/Pose pose\nfloat64[36] covariance" +
           separator +
           "geometry_msgs/Pose\ngeometry_msgs/Point position\n"
           "geometry_msgs/Quaternion orientation" +
           separator + "geometry_msgs/Point\nfloat64 x\nfloat64 y\nfloat64 z" + quaternion +
           separator +
           "geometry_msgs/TwistWithCovariance\ngeometry_msgs/Twist twist\nfloat64[36] covariance" +
           separator +
           "geometry_msgs/Twist\ngeometry_msgs/Vector3 linear\ngeometry_msgs/Vector3 angular" +
           vector3;
  }
  if (type == kRosImuType) {
    return "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\n"
           "float64[9] orientation_covariance\ngeometry_msgs/Vector3 angular_velocity\n"
           "float64[9] angular_velocity_covariance\ngeometry_msgs/Vector3 linear_acceleration\n"
           "float64[9] linear_acceleration_covariance" +
           header + quaternion + vector3;
  }
  if (type == kRosTfMessageType) {
    return "geometry_msgs/TransformStamped[] transforms" + separator +
           "geometry_msgs/TransformStamped\nstd_msgs/Header header\nstring child_frame_id\n"
           "geometry_msgs/Transform transform" +
           header + separator +
           "geometry_msgs/Transform\ngeometry_msgs/Vector3 translation\n"
           "geometry_msgs/Quaternion rotation" +
           vector3 + quaternion;
  }
  return "";
}

}  // namespace stcalib
