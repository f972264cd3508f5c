// report.html of a calibrate run folder (docs/output.md).
#include "apps/report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

#include "core/io/text.h"

namespace stcalib::cli {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string Escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string Base64(const std::string& bytes) {
  static const char kTable[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3) {
    uint32_t n = static_cast<uint8_t>(bytes[i]) << 16;
    if (i + 1 < bytes.size()) n |= static_cast<uint8_t>(bytes[i + 1]) << 8;
    if (i + 2 < bytes.size()) n |= static_cast<uint8_t>(bytes[i + 2]);
    out += kTable[(n >> 18) & 63];
    out += kTable[(n >> 12) & 63];
    out += i + 1 < bytes.size() ? kTable[(n >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? kTable[n & 63] : '=';
  }
  return out;
}

Status ReadBytes(const std::string& path, std::string* bytes) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::Error(path + ": cannot be read");
  std::ostringstream s;
  s << in.rdbuf();
  *bytes = s.str();
  return Status::Ok();
}

// An <img> of a PNG of the run folder, inlined.
Status ImageTag(const std::string& path, const std::string& alt, std::string* tag) {
  std::string bytes;
  STCALIB_RETURN_IF_ERROR(ReadBytes(path, &bytes));
  *tag = "<img alt=\"" + Escape(alt) + "\" src=\"data:image/png;base64," + Base64(bytes) + "\">";
  return Status::Ok();
}

std::string Number(double value, const char* format) {
  char text[64];
  std::snprintf(text, sizeof(text), format, value);
  return text;
}

// per_frame.csv as columns by name (numbers; NaN where a cell is empty or not a number).
struct Table {
  std::map<std::string, std::vector<double>> columns;
  size_t rows = 0;
};

std::vector<std::string> SplitCsvLine(const std::string& line) {
  std::vector<std::string> cells(1);
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (c == '"') {
      if (quoted && i + 1 < line.size() && line[i + 1] == '"') {
        cells.back() += '"';
        ++i;
      } else {
        quoted = !quoted;
      }
    } else if (c == ',' && !quoted) {
      cells.emplace_back();
    } else {
      cells.back() += c;
    }
  }
  return cells;
}

Status ReadTable(const std::string& path, Table* table) {
  std::vector<std::string> lines;
  STCALIB_RETURN_IF_ERROR(ReadLines(path, &lines));
  if (lines.empty()) return Status::Error(path + ": empty (no header)");
  const std::vector<std::string> header = SplitCsvLine(lines[0]);
  for (size_t r = 1; r < lines.size(); ++r) {
    if (lines[r].empty()) continue;
    const std::vector<std::string> cells = SplitCsvLine(lines[r]);
    for (size_t c = 0; c < header.size(); ++c) {
      double value = std::nan("");
      if (c < cells.size() && !cells[c].empty()) {
        char* end = nullptr;
        const double parsed = std::strtod(cells[c].c_str(), &end);
        if (end != cells[c].c_str() && *end == '\0') value = parsed;
      }
      table->columns[header[c]].push_back(value);
    }
    ++table->rows;
  }
  return Status::Ok();
}

struct Series {
  std::string name, colour;
  std::vector<double> value, std;  // NaN: no value / no band at that frame
};

// An SVG panel: each series against the frame, with a ±std band where there is one.
std::string Panel(const std::string& title, const std::string& unit, const std::vector<double>& x,
                  const std::vector<Series>& series) {
  constexpr double kWidth = 900, kHeight = 240, kLeft = 60, kRight = 20, kTop = 28, kBottom = 30;
  double lo = 0, hi = 0, x_lo = x.empty() ? 0 : x.front(), x_hi = x.empty() ? 1 : x.back();
  for (const Series& s : series) {
    for (size_t i = 0; i < s.value.size(); ++i) {
      if (!std::isfinite(s.value[i])) continue;
      const double band = i < s.std.size() && std::isfinite(s.std[i]) ? s.std[i] : 0;
      lo = std::min(lo, s.value[i] - band);
      hi = std::max(hi, s.value[i] + band);
    }
  }
  if (hi - lo < 1e-9) hi = lo + 1;
  if (x_hi - x_lo < 1e-9) x_hi = x_lo + 1;
  auto px = [&](double v) {
    return kLeft + (v - x_lo) / (x_hi - x_lo) * (kWidth - kLeft - kRight);
  };
  auto py = [&](double v) { return kTop + (hi - v) / (hi - lo) * (kHeight - kTop - kBottom); };
  std::string svg = "<svg class=\"panel\" viewBox=\"0 0 900 240\" width=\"900\" height=\"240\">";
  svg += "<text x=\"" + Number(kLeft, "%.0f") + "\" y=\"18\" class=\"title\">" + Escape(title) +
         " [" + Escape(unit) + "]</text>";
  svg += "<line x1=\"" + Number(kLeft, "%.1f") + "\" x2=\"" + Number(kWidth - kRight, "%.1f") +
         "\" y1=\"" + Number(py(0), "%.1f") + "\" y2=\"" + Number(py(0), "%.1f") +
         "\" class=\"zero\"/>";
  svg += "<text x=\"4\" y=\"" + Number(py(hi) + 10, "%.1f") + "\">" + Number(hi, "%.3g") +
         "</text><text x=\"4\" y=\"" + Number(py(lo), "%.1f") + "\">" + Number(lo, "%.3g") +
         "</text><text x=\"" + Number(kWidth - kRight - 60, "%.0f") + "\" y=\"" +
         Number(kHeight - 8, "%.0f") + "\">frame</text>";
  for (const double tick : {x_lo, x_hi}) {
    svg += "<text x=\"" + Number(px(tick) - 4, "%.1f") + "\" y=\"" + Number(kHeight - 8, "%.0f") +
           "\">" + Number(tick, "%.0f") + "</text>";
  }
  double legend_x = kLeft + 240;
  for (const Series& s : series) {
    std::string upper, lower, line;
    for (size_t i = 0; i < s.value.size() && i < x.size(); ++i) {
      if (!std::isfinite(s.value[i])) continue;
      line += Number(px(x[i]), "%.1f") + "," + Number(py(s.value[i]), "%.1f") + " ";
      if (i < s.std.size() && std::isfinite(s.std[i])) {
        upper += Number(px(x[i]), "%.1f") + "," + Number(py(s.value[i] + s.std[i]), "%.1f") + " ";
        lower = Number(px(x[i]), "%.1f") + "," + Number(py(s.value[i] - s.std[i]), "%.1f") + " " +
                lower;
      }
    }
    if (!upper.empty()) {
      svg += "<polygon class=\"band\" fill=\"" + s.colour + "\" points=\"" + upper + lower + "\"/>";
    }
    svg += "<polyline fill=\"none\" stroke=\"" + s.colour + "\" points=\"" + line + "\"/>";
    svg += "<text x=\"" + Number(legend_x, "%.0f") + "\" y=\"18\" fill=\"" + s.colour + "\">" +
           Escape(s.name) + "</text>";
    legend_x += 110;
  }
  return svg + "</svg>";
}

const char kHead[] =
    "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
    "<title>stcalib report</title><style>"
    "body{font-family:sans-serif;margin:24px;max-width:1400px}"
    "table{border-collapse:collapse;margin:8px 0}td,th{border:1px solid #bbb;padding:3px 8px;"
    "text-align:left;vertical-align:top}th{background:#eee}"
    ".whole{color:#060}.partial{color:#a60}.none{color:#b00}.held{color:#a60;font-weight:bold}"
    ".failed{background:#fdd}.strip{overflow-x:auto}.strip figure{margin:4px 0 12px 0}"
    ".strip img{display:block}"
    "svg text{font-size:12px}svg .title{font-weight:bold}svg .zero{stroke:#999}"
    "svg .band{opacity:0.2}svg polyline{stroke-width:1.5}"
    "</style></head><body>\n";

// Marks the page once every image decoded (read by the browser test; nothing is fetched).
const char kTail[] =
    "<script>window.addEventListener('load',function(){var i=document.images,n=0;"
    "for(var k=0;k<i.length;k++){if(i[k].complete&&i[k].naturalWidth>0)n++;}"
    "document.body.setAttribute('data-images',n+'/'+i.length);});</script>\n</body></html>\n";

// The frames/<prefix>F.png pictures of a run folder, in frame order, with each frame's
// captions, one figure per picture.
Status FrameStrip(const std::string& run_dir, const std::vector<std::string>& prefixes,
                  const std::vector<std::string>& captions, std::string* html) {
  std::vector<std::string> frames;
  if (fs::is_directory(run_dir + "/frames")) {
    for (const auto& entry : fs::directory_iterator(run_dir + "/frames")) {
      const std::string name = entry.path().filename().string();
      const std::string& first = prefixes.front();
      if (name.rfind(first, 0) == 0 && entry.path().extension() == ".png") {
        frames.push_back(name.substr(first.size(), name.size() - first.size() - 4));
      }
    }
  }
  std::sort(frames.begin(), frames.end(),
            [](const std::string& a, const std::string& b) { return std::stoi(a) < std::stoi(b); });
  for (const std::string& frame : frames) {
    *html += "<div class=\"strip\">";
    for (size_t k = 0; k < prefixes.size(); ++k) {
      std::string tag;
      const std::string caption = "frame " + frame + ", " + captions[k];
      STCALIB_RETURN_IF_ERROR(
          ImageTag(run_dir + "/frames/" + prefixes[k] + frame + ".png", caption, &tag));
      *html += "<figure>" + tag + "<figcaption>" + Escape(caption) + "</figcaption></figure>";
    }
    *html += "</div>";
  }
  if (frames.empty()) *html += "<p>No frame was used: nothing to draw.</p>";
  return Status::Ok();
}

std::string RunSection(const json& run) {
  return "<section id=\"run\"><h2>Run</h2><table><tr><th>command</th><td><code>" +
         Escape(run["command"].get<std::string>()) + "</code></td></tr><tr><th>input</th><td>" +
         Escape(run["input"].get<std::string>()) + "</td></tr><tr><th>version</th><td>" +
         Escape(run["stcalib_version"].get<std::string>()) + "</td></tr></table></section>\n";
}

// The keys of `object` among `keys` that it lacks, comma-separated; empty when none.
std::string MissingKeys(const json& object, std::initializer_list<const char*> keys) {
  std::string missing;
  for (const char* key : keys) {
    if (!object.contains(key)) missing += std::string(missing.empty() ? "" : ", ") + key;
  }
  return missing;
}

Status ReadJsonObject(const std::string& path, json* object) {
  std::string text;
  STCALIB_RETURN_IF_ERROR(ReadBytes(path, &text));
  *object = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (object->is_discarded() || !object->is_object()) {
    return Status::Error(path + ": not a JSON object");
  }
  return Status::Ok();
}

// The page of a `check --out` folder (check.json and frames/checked_F.png).
Status WriteCheckReport(const std::string& run_dir) {
  const std::string path = run_dir + "/check.json";
  json check;
  STCALIB_RETURN_IF_ERROR(ReadJsonObject(path, &check));
  const std::string missing = MissingKeys(
      check, {"stcalib_version", "command", "input", "calibration", "time_offset_s", "answer",
              "reason", "frames_used", "blocks", "block_frames", "t_quantile", "axes",
              "rotation_offset_deg", "rotation_std_deg", "tolerance_rotation_deg"});
  if (!missing.empty()) {
    return Status::Error(path + ": no " + missing +
                         " (written by another stcalib version; this one is " + STCALIB_VERSION +
                         "): run check again");
  }
  try {
    const std::string answer = check["answer"].get<std::string>();
    std::string html = kHead;
    html += "<h1>stcalib check report</h1>\n<section id=\"verdict\"><h2>Verdict</h2><p class=\"" +
            std::string(answer == "holds" ? "whole"
                        : answer == "off" ? "none"
                                          : "partial") +
            "\"><b>" +
            (answer == "holds" ? "The calibration holds"
             : answer == "off" ? "The calibration is off"
                               : "This drive cannot tell") +
            "</b>: " + Escape(check["reason"].get<std::string>()) +
            "</p><p>Checked: " + Escape(check["calibration"].get<std::string>()) +
            ", time offset " + Number(1000 * check["time_offset_s"].get<double>(), "%+.1f") +
            " ms.</p></section>\n";
    const double t = check["t_quantile"].get<double>();
    html += "<section id=\"axes\"><h2>Per axis</h2><p>Offset: the drive's optimum near the "
            "checked calibration minus the calibration; std: its spread over the drive (the "
            "larger of a delete-a-block jackknife over " +
            std::to_string(check["blocks"].get<int>()) + " blocks of " +
            std::to_string(check["block_frames"].get<int>()) + " frames and the refinement's "
            "covariance); t = " + Number(t, "%.2f") +
            ", the one-sided 99 % quantile of Student's t over the blocks. The rotation lies " +
            Number(check["rotation_offset_deg"].get<double>(), "%.2f") + "° from the optimum (std " +
            Number(check["rotation_std_deg"].get<double>(), "%.2f") + "° along it; tolerance " +
            Number(check["tolerance_rotation_deg"].get<double>(), "%.2f") +
            "°): off beyond tolerance + t·std. An axis is resolved when t·std ≤ tolerance, and a "
            "resolved translation axis or δ off beyond tolerance + t·std.</p><table><tr><th>axis</th><th>offset</th><th>std</th>"
            "<th>tolerance</th><th>answer</th></tr>";
    for (const json& a : check["axes"]) {
      const std::string name = a["axis"].get<std::string>();
      const bool off = a["off"].get<bool>(), resolved = a["resolved"].get<bool>();
      const bool degrees = name.find("_deg") != std::string::npos;
      const bool metres = name.find("_m") != std::string::npos && !degrees;
      const double scale = degrees ? 1 : metres ? 100 : 1000;
      const char* unit = degrees ? " °" : metres ? " cm" : " ms";
      html += std::string("<tr") + (off ? " class=\"failed\"" : "") + "><td>" + Escape(name) +
              "</td><td>" + Number(scale * a["offset"].get<double>(), "%+.2f") + unit +
              "</td><td>" + Number(scale * a["std"].get<double>(), "%.2f") + unit + "</td><td>" +
              Number(scale * a["tolerance"].get<double>(), "%.2f") + unit + "</td><td>" +
              (off ? "off" : resolved ? "within" : "not resolved") + "</td></tr>";
    }
    html +=
        "</table></section>\n<section id=\"overlays\"><h2>LiDAR edges on the image</h2>"
        "<p>At the checked calibration, at the image's full resolution (green: within 2 px of "
        "an image edge of its direction).</p>";
    STCALIB_RETURN_IF_ERROR(FrameStrip(run_dir, {"checked_"}, {"checked calibration"}, &html));
    html += "</section>\n" + RunSection(check) + kTail;
    return WriteTextFile(run_dir + "/report.html", html);
  } catch (const json::exception& e) {
    return Status::Error(path + ": a key has the wrong type (" + e.what() + ")");
  }
}

}  // namespace

const char* StcalibVersion() { return STCALIB_VERSION; }

Status WriteRunReport(const std::string& run_dir) {
  const std::string result_path = run_dir + "/result.json";
  if (!fs::exists(result_path)) {
    if (fs::exists(run_dir + "/check.json")) return WriteCheckReport(run_dir);
    return Status::Error(result_path + ": missing (and no check.json): " + run_dir +
                         " is no run folder of calibrate --out or check --out");
  }
  json result;
  STCALIB_RETURN_IF_ERROR(ReadJsonObject(result_path, &result));
  const std::string missing =
      MissingKeys(result, {"stcalib_version", "command", "input", "claim", "held_axes", "reason",
                           "verdict_rules", "rpy_deg", "T_camera_lidar", "time_offset_s", "std",
                           "observable", "start", "time_offset_vs_forward"});
  if (!missing.empty()) {
    return Status::Error(result_path + ": no " + missing +
                         " (written by another stcalib version; this one is " + StcalibVersion() +
                         "): run calibrate again");
  }
  Table table;
  STCALIB_RETURN_IF_ERROR(ReadTable(run_dir + "/per_frame.csv", &table));
  try {
    const std::vector<std::string> held = result["held_axes"].get<std::vector<std::string>>();
    auto is_held = [&](const std::string& axis) {
      return std::find(held.begin(), held.end(), axis) != held.end();
    };
    const std::string claim = result["claim"].get<std::string>();
    std::string html = std::string(kHead) + "<h1>stcalib calibration report</h1>\n";
    // The verdict.
    html += "<section id=\"verdict\"><h2>Verdict</h2><p class=\"" + claim + "\"><b>" +
            (claim == "whole"     ? "Claimed"
             : claim == "partial" ? "Claimed partly"
                                  : "Not claimed") +
            "</b>: " + Escape(result["reason"].get<std::string>()) +
            "</p><table><tr><th>rule</th><th>passed</th><th>measured</th></tr>";
    for (const json& rule : result["verdict_rules"]) {
      const bool passed = rule["passed"].get<bool>();
      html += std::string("<tr") + (passed ? "" : " class=\"failed\"") + "><td>" +
              Escape(rule["name"].get<std::string>()) + "</td><td>" + (passed ? "yes" : "no") +
              "</td><td>" + Escape(rule["detail"].get<std::string>()) + "</td></tr>";
    }
    html += "</table></section>\n";
    // The estimate per axis.
    const json& start = result["start"];
    const json& reference = result.contains("error") ? result["error"]
                            : result.contains("agreement_with_drive_calibration")
                                ? result["agreement_with_drive_calibration"]
                                : json();
    const std::string reference_name =
        result.contains("error") ? "error vs truth" : "vs the drive's calibration";
    const json& T = result["T_camera_lidar"];
    struct Axis {
      const char* name;
      const char* unit;
      double scale;
      double start, estimate;
    };
    const std::vector<Axis> axes = {
        {"roll_deg", "deg", 1, start["rpy_deg"]["roll"], result["rpy_deg"]["roll"]},
        {"pitch_deg", "deg", 1, start["rpy_deg"]["pitch"], result["rpy_deg"]["pitch"]},
        {"yaw_deg", "deg", 1, start["rpy_deg"]["yaw"], result["rpy_deg"]["yaw"]},
        {"x_m", "cm", 100, start["translation_m"]["x"], T[3]},
        {"y_m", "cm", 100, start["translation_m"]["y"], T[7]},
        {"z_m", "cm", 100, start["translation_m"]["z"], T[11]},
        {"time_offset_s", "ms", 1000, start["time_offset_s"], result["time_offset_s"]}};
    html +=
        "<section id=\"estimate\"><h2>Estimate</h2><table><tr><th>axis</th><th>unit</th>"
        "<th>start</th><th>estimate</th><th>std</th><th>observed</th><th>" +
        Escape(reference_name) + "</th></tr>";
    for (const Axis& a : axes) {
      const json& std_value = result["std"][a.name];
      const bool held = is_held(a.name);
      html +=
          std::string("<tr><td>") + a.name + "</td><td>" + a.unit + "</td><td>" +
          Number(a.scale * a.start, "%+.3f") + "</td><td>" + Number(a.scale * a.estimate, "%+.3f") +
          "</td><td>" +
          (std_value.is_number() ? Number(a.scale * std_value.get<double>(), "%.3f") : "—") +
          "</td><td>" +
          (held ? "<span class=\"held\">held at the start</span>"
           : result["observable"][a.name].get<bool>() ? "yes"
                                                      : "no (rests on its prior)") +
          "</td><td>" +
          (reference.contains(a.name) ? Number(a.scale * reference[a.name].get<double>(), "%+.3f")
                                      : "—") +
          "</td></tr>";
    }
    html += "</table></section>\n";
    // The frame strip.
    html +=
        "<section id=\"overlays\"><h2>LiDAR edges on the image</h2><p>Each frame at the start "
        "and at the estimate, at the image's full resolution (green: within 2 px of an image "
        "edge of its direction).</p>";
    STCALIB_RETURN_IF_ERROR(
        FrameStrip(run_dir, {"start_", "estimate_"}, {"start", "estimate"}, &html));
    html += "</section>\n";
    // The convergence curves, against the reference, with the refinement's std bands.
    html +=
        "<section id=\"curves\"><h2>Convergence</h2><p>Each axis of the online estimate "
        "after every frame, " +
        Escape(reference.is_null() ? "as estimated" : reference_name) +
        "; bands: ±1 std of that frame's refinement.</p>";
    const std::vector<double>& frames = table.columns["frame"];
    auto series = [&](const char* column, const char* std_column, const char* name,
                      const char* colour, double scale, double reference_value) {
      Series s{name, colour, {}, {}};
      for (size_t i = 0; i < table.rows; ++i) {
        s.value.push_back(scale * (table.columns[column][i] - reference_value));
        s.std.push_back(scale * table.columns[std_column][i]);
      }
      return s;
    };
    // The reference per axis: the estimate minus its error (zero without one).
    auto reference_of = [&](const Axis& a) {
      return reference.contains(a.name) ? a.estimate - reference[a.name].get<double>() : 0.0;
    };
    const char* colours[] = {"#c00", "#080", "#00c"};
    std::vector<Series> rotation, translation;
    for (int k = 0; k < 3; ++k) {
      const std::string axis = axes[k].name;
      const std::string short_name = axis.substr(0, axis.find('_'));
      rotation.push_back(series(axes[k].name, (short_name + "_std_deg").c_str(), short_name.c_str(),
                                colours[k], 1, reference_of(axes[k])));
      const std::string t_axis = axes[3 + k].name;
      translation.push_back(
          series(axes[3 + k].name, (t_axis.substr(0, 1) + "_std_m").c_str(),
                 (t_axis.substr(0, 1) + (is_held(t_axis) ? " (held)" : "")).c_str(), colours[k],
                 100, reference_of(axes[3 + k])));
    }
    const std::vector<Series> time = {series("time_offset_s", "time_offset_std_s",
                                             is_held("time_offset_s") ? "δ (held)" : "δ", "#606",
                                             1000, reference_of(axes[6]))};
    html += Panel("rotation", "deg", frames, rotation) +
            Panel("translation", "cm", frames, translation) +
            Panel("time offset δ", "ms", frames, time);
    html += "</section>\n";
    // δ against the translation along travel.
    const json& pair = result["time_offset_vs_forward"];
    const std::string rests_on = pair["rests_on"].get<std::string>();
    html += "<section id=\"time-forward\"><h2>Time offset and the translation along travel</h2><p>";
    if (rests_on == "window") {
      html += "The drive separated δ from the translation along travel: both moved with the data.";
    } else {
      html +=
          "A time offset δ moves the LiDAR by speed × δ along the direction of travel, "
          "which a shift of the translation along travel also does: on a straight road at "
          "constant speed the two cannot be told apart (δ error = forward error ÷ speed). ";
      html += rests_on == "start" ? "Here δ was held at its start."
                                  : "Here δ rests on the prior of the translation along travel.";
      if (pair["measured"].get<bool>()) {
        html += " With both free, δ's std was " +
                Number(1000 * pair["time_offset_std_s"].get<double>(), "%.1f") +
                " ms and the translation's " +
                Number(100 * pair["forward_std_m"].get<double>(), "%.1f") + " cm, correlated " +
                Number(pair["correlation"].get<double>(), "%+.2f") + ".";
      }
    }
    html += "</p></section>\n";
    html += RunSection(result) + kTail;
    return WriteTextFile(run_dir + "/report.html", html);
  } catch (const json::exception& e) {
    return Status::Error(result_path + ": a key has the wrong type (" + e.what() + ")");
  }
}

}  // namespace stcalib::cli
