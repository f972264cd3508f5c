// The project's documents against the code (issue 54): README.md stays short, nothing cites a
// document outside the repository, README's quick start runs as written, and docs/output.md
// names every key result.json can hold.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "test/test_util.h"

namespace stcalib {
namespace {

namespace fs = std::filesystem;

const std::string kSource = STCALIB_SOURCE_DIR;

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

int RunShell(const std::string& command, std::string* output) {
  const testing::CommandResult result = testing::RunCommand(command);
  *output += result.output;
  return result.exit_code;
}

TEST(Docs, ReadmeIsAtMost200Lines) {
  const std::string readme = testing::ReadFile(kSource + "/README.md");
  ASSERT_FALSE(readme.empty()) << kSource << "/README.md";
  EXPECT_LE(Lines(readme).size(), 200u) << "README.md grew past 200 lines: move detail to docs/";
}

// The code and documents cite docs/ inside the repository, never the shared documents beside
// it, nor (outside docs/) a bare method.md, which would be the shared one.
TEST(Docs, NothingCitesADocumentOutsideTheRepository) {
  const std::string shared = std::string("../shared/") + "docs";
  // "method.md" not preceded by a path ("docs/method.md") or a word character.
  auto cites_bare_method = [](const std::string& line) {
    for (size_t at = line.find("method.md"); at != std::string::npos;
         at = line.find("method.md", at + 1)) {
      const char before = at == 0 ? ' ' : line[at - 1];
      if (before != '/' && before != '_' && !std::isalnum(static_cast<unsigned char>(before))) {
        return true;
      }
    }
    return false;
  };
  int files = 0;
  for (auto it = fs::recursive_directory_iterator(kSource);
       it != fs::recursive_directory_iterator(); ++it) {
    const std::string name = it->path().filename().string();
    if (it->is_directory() && (name == ".git" || name.rfind("build", 0) == 0)) {
      it.disable_recursion_pending();
      continue;
    }
    if (!it->is_regular_file() || name == "docs_test.cc") continue;
    const bool in_docs = it->path().parent_path().filename() == "docs";
    const std::string ext = it->path().extension().string();
    if (ext != ".h" && ext != ".cc" && ext != ".md" && ext != ".txt" && ext != ".flags" &&
        ext != "" && ext != ".sh") {
      continue;
    }
    ++files;
    int number = 0;
    for (const std::string& line : Lines(testing::ReadFile(it->path().string()))) {
      ++number;
      EXPECT_FALSE(line.find(shared) != std::string::npos || (!in_docs && cites_bare_method(line)))
          << it->path().string() << ":" << number
          << " cites a document outside the repository: " << line;
    }
  }
  EXPECT_GT(files, 50);
}

// Every command of README's quick start (the ```sh block) runs as written from the repository
// root and exits 0; build/apps/stcalib is this build's binary.
TEST(Docs, ReadmeQuickStartRunsAsWritten) {
  if (!testing::HaveKitti()) GTEST_SKIP() << "../shared/data is absent: the quick start reads it";
  const std::vector<std::string> lines = Lines(testing::ReadFile(kSource + "/README.md"));
  std::vector<std::string> commands;
  bool in_block = false;
  for (const std::string& line : lines) {
    if (line == "```sh") {
      in_block = true;
    } else if (in_block && line.rfind("```", 0) == 0) {
      in_block = false;
    } else if (in_block && !line.empty() && line[0] != '#') {
      commands.push_back(line);
    }
  }
  ASSERT_FALSE(commands.empty()) << "README.md has no ```sh block";
  const testing::ScopedTempDir tmp;
  for (std::string command : commands) {
    // The README's /tmp/ becomes the test's folder, then its binary this build's: in that order,
    // so that a clone inside the temporary folder keeps the binary's own path.
    for (size_t at = command.find("/tmp/"); at != std::string::npos;
         at = command.find("/tmp/", at + tmp.path().size() + 1)) {
      command.replace(at, 5, tmp.path() + "/");
    }
    const std::string binary = "build/apps/stcalib";
    if (command.rfind(binary, 0) == 0) command = STCALIB_BINARY + command.substr(binary.size());
    std::string output;
    const int code = RunShell("cd " + kSource + " && " + command, &output);
    EXPECT_EQ(code, 0) << command << "\n" << output;
  }
}

// Dotted paths of every key in `json` that holds a value, not an object ("a.b"; arrays of
// objects as "a" and "a[].b").
void KeyPaths(const nlohmann::json& json, const std::string& prefix, std::set<std::string>* out) {
  if (json.is_object()) {
    for (auto it = json.begin(); it != json.end(); ++it) {
      const std::string path = prefix.empty() ? it.key() : prefix + "." + it.key();
      if (!it.value().is_object()) out->insert(path);
      KeyPaths(it.value(), path, out);
    }
  } else if (json.is_array()) {
    for (const nlohmann::json& element : json) {
      if (element.is_object()) KeyPaths(element, prefix + "[]", out);
    }
  }
}

// Every key of result.json written on a simulated drive, and every per_frame.csv column, is in
// docs/output.md (in backticks).
TEST(Docs, OutputDocumentNamesEveryResultKeyAndColumn) {
  const testing::ScopedTempDir tmp;
  std::string output;
  ASSERT_EQ(RunShell(std::string(STCALIB_BINARY) + " simulate --out=" + tmp.path() +
                         "/sim --frames=6 --seed=3 --dynamic_objects=2",
                     &output),
            0)
      << output;
  std::string drive;
  for (const auto& entry : fs::recursive_directory_iterator(tmp.path() + "/sim")) {
    const std::string name = entry.path().filename().string();
    if (entry.is_directory() && name.size() > 5 && name.substr(name.size() - 5) == "_sync") {
      drive = entry.path().string();
    }
  }
  ASSERT_FALSE(drive.empty()) << output;
  // Converged or not, result.json is written (exit 0 or 1).
  const int code = RunShell(std::string(STCALIB_BINARY) + " calibrate --flagfile=" + kSource +
                                "/configs/sim.flags --drive=" + drive +
                                " --perturb_rot_deg=0.5 --seed=1 --out=" + tmp.path() + "/run",
                            &output);
  ASSERT_TRUE(code == 0 || code == 1) << output;
  const nlohmann::json result =
      nlohmann::json::parse(testing::ReadFile(tmp.path() + "/run/result.json"));
  std::set<std::string> keys;
  KeyPaths(result, "", &keys);
  const std::string doc = testing::ReadFile(kSource + "/docs/output.md");
  ASSERT_FALSE(doc.empty());
  for (const std::string& key : keys) {
    EXPECT_NE(doc.find("`" + key + "`"), std::string::npos)
        << "result.json key " << key << " is not in docs/output.md";
  }
  const std::vector<std::string> csv = Lines(testing::ReadFile(tmp.path() + "/run/per_frame.csv"));
  ASSERT_FALSE(csv.empty());
  std::istringstream header(csv.front());
  for (std::string column; std::getline(header, column, ',');) {
    EXPECT_NE(doc.find("`" + column + "`"), std::string::npos)
        << "per_frame.csv column " << column << " is not in docs/output.md";
  }
}

}  // namespace
}  // namespace stcalib
