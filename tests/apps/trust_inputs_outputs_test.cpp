// Issue 18 (inputs, outputs): through the real binary, as a user or a hostile local user meets them.
// Outputs stay inside --out, are written whole or not at all, never through a planted symlink, and an
// unwritable --out fails before the run; check-config refuses everything calibrate would, with one exit
// code per mistake across commands; a poses CSV with absurd rows is refused with the line.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "rigcal/core/pcd_io.hpp"
#include "run_command.hpp"
#include "test_data.hpp"

namespace rigcal::test {
namespace {

namespace fs = std::filesystem;

// A valid two-lidar rig with `sensors_extra` appended to the second sensor's entry and `extra` at the end.
fs::path writeRig(const TempDir& dir, const std::string& second_name = "left", const std::string& second_extra = "",
                  const std::string& extra = "") {
  const auto path = dir / "rig.yaml";
  std::ofstream f(path);
  f << "rig: trust\n"
       "sensors:\n"
       "  - name: top\n"
       "    model: VLP-16\n"
       "    source: {port: 2368}\n"
       "  - name: " << second_name << "\n"
       "    model: VLP-16\n"
       "    source: {port: 2399}\n"
    << second_extra
    << "roles:\n"
       "  mapping_lidar: top\n"
       "  calibration_lidars: ['" << second_name << "']\n"
    << extra;
  return path;
}

std::vector<std::string> temporaries(const fs::path& dir) {
  std::vector<std::string> found;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.path().filename().string().find(".tmp.") != std::string::npos) found.push_back(e.path().string());
  return found;
}

// check-config and calibrate both refuse the rig with exit 3 and a message at the rig file's position.
void expectRefusedByBoth(const fs::path& rig, const std::string& message) {
  const auto check = runRigcal({"check-config", rig.string()});
  EXPECT_EQ(check.exit_code, 3) << check.out << check.err;
  EXPECT_NE(check.err.find(rig.string() + ":"), std::string::npos) << check.err;
  EXPECT_NE(check.err.find(message), std::string::npos) << check.err;
  EXPECT_EQ(std::count(check.err.begin(), check.err.end(), '\n'), 1) << check.err;
  TempDir out;
  const auto calibrate = runRigcal({"calibrate", "--config", rig.string(), "--pcap", rig.string(), "--out",
                                    (out / "o").string()});
  EXPECT_EQ(calibrate.exit_code, 3) << calibrate.err;
  EXPECT_NE(calibrate.err.find(message), std::string::npos) << calibrate.err;
}

TEST(TrustOutputs, ASensorNameCannotLeaveTheOutputFolder) {
  TempDir dir;
  for (const std::string name : {"../escaped", "..", "a/b", "sp ace"}) {
    const auto rig = writeRig(dir, name);
    SCOPED_TRACE(name);
    expectRefusedByBoth(rig, "sensor name '" + name + "' is not allowed");
    EXPECT_NE(runRigcal({"check-config", rig.string()}).err.find("rig.yaml:6:"), std::string::npos);
  }
  EXPECT_EQ(runRigcal({"check-config", writeRig(dir, "front_left-2.b").string()}).exit_code, 0);
}

// A symlink planted at an output's final name is replaced, not followed: the file it points to is
// untouched; and no temporary file is left behind.
TEST(TrustOutputs, APlantedSymlinkIsReplacedNotFollowed) {
  TempDir dir;
  const auto victim = dir / "victim.txt";
  std::ofstream(victim) << "precious";
  fs::create_directories(dir / "out");
  fs::create_symlink(victim, dir / "out" / "rig.yaml");
  fs::create_symlink(victim, dir / "out" / "recording.pcap");
  const auto r = runRigcal({"sim", "--scenario", "parking-lot", "--duration", "0.3", "--out", (dir / "out").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(fileContents(victim), "precious");
  EXPECT_FALSE(fs::is_symlink(dir / "out" / "rig.yaml"));
  EXPECT_FALSE(fs::is_symlink(dir / "out" / "recording.pcap"));
  EXPECT_NE(fileContents(dir / "out" / "rig.yaml").find("sensors:"), std::string::npos);
  EXPECT_TRUE(temporaries(dir.path()).empty());
}

// A write that fails half-way (here the file-size limit, as a full disk would) is an error naming the
// file, and leaves neither a half file at the final name nor a temporary one.
TEST(TrustOutputs, AFailedWriteLeavesNoHalfFile) {
  TempDir dir;
  const std::string cmd = "trap '' XFSZ; ulimit -f 2048; exec '" + rigcalBinary().string() +
                          "' sim --scenario parking-lot --duration 0.5 --out '" + (dir / "out").string() +
                          "' >'" + (dir / "stdout").string() + "' 2>'" + (dir / "stderr").string() + "'";
  const int status = std::system(("bash -c \"" + cmd + "\"").c_str());
  ASSERT_TRUE(WIFEXITED(status));
  const std::string err = fileContents(dir / "stderr");
  EXPECT_EQ(WEXITSTATUS(status), 1) << err;
  EXPECT_NE(err.find("recording.pcap: write failed"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(dir / "out" / "recording.pcap")) << "a half capture under the final name";
  EXPECT_TRUE(temporaries(dir.path()).empty());
}

TEST(TrustOutputs, AnUnwritableOutFolderFailsBeforeTheRun) {
  TempDir dir;
  const auto rig = writeRig(dir);
  std::ofstream(dir / "file") << "x";
  RIGCAL_REQUIRE_DATA(pcap, "velodyne/vlp16_20hz_veloview.pcap");
  const auto under_file = runRigcal({"calibrate", "--config", rig.string(), "--pcap", pcap.string(), "--out",
                                     (dir / "file" / "out").string()});
  EXPECT_EQ(under_file.exit_code, 2) << under_file.err;
  EXPECT_NE(under_file.err.find("--out " + (dir / "file" / "out").string() + ": cannot create"), std::string::npos)
      << under_file.err;
  EXPECT_EQ(under_file.out.find("mapper"), std::string::npos) << "failed before the run: " << under_file.out;

  // A read-only folder: root writes anyway, so as root the check runs as nobody.
  std::vector<std::string> launcher;
  if (::geteuid() == 0) {
    if (std::system("setpriv --version >/dev/null 2>&1") != 0) GTEST_SKIP() << "setpriv is needed to drop root";
    launcher = {"setpriv", "--reuid=65534", "--regid=65534", "--clear-groups"};
  }
  fs::create_directories(dir / "ro");
  fs::permissions(dir.path(), fs::perms::owner_all | fs::perms::others_read | fs::perms::others_exec);
  fs::permissions(dir / "ro", fs::perms::owner_read | fs::perms::owner_exec | fs::perms::others_read |
                                  fs::perms::others_exec);
  fs::permissions(rig, fs::perms::owner_all | fs::perms::others_read);
  const auto ro = RigcalProcess({"calibrate", "--config", rig.string(), "--pcap", pcap.string(), "--out",
                                 (dir / "ro").string()},
                                launcher)
                      .wait();
  EXPECT_EQ(ro.exit_code, 2) << ro.err;
  EXPECT_NE(ro.err.find("not writable"), std::string::npos) << ro.err;
  EXPECT_TRUE(fs::is_empty(dir / "ro"));
}

// The default rig with `from` replaced by `to` (each must occur).
fs::path rigWith(const TempDir& dir, const std::string& from, const std::string& to) {
  std::string text = fileContents(writeRig(dir));
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  std::ofstream(dir / "rig.yaml", std::ios::trunc) << text;
  return dir / "rig.yaml";
}

TEST(TrustConfig, CheckConfigRefusesWhatCalibrateWould) {
  TempDir dir;
  const std::string left = "model: VLP-16\n    source: {port: 2399}\n";
  const auto withLeft = [&](const std::string& replacement) { return rigWith(dir, left, replacement); };
  fs::create_directories(dir / "folder");
  std::ofstream(dir / "garbage.yaml") << "lasers: [1, 2\n";
  fs::resize_file((std::ofstream(dir / "huge.yaml"), dir / "huge.yaml"), 17u << 20);  // sparse, 17 MiB
  struct Case {
    std::string what, replacement, message;
  };
  const std::vector<Case> cases = {
      {"unknown model", "model: VLP-99\n    source: {port: 2399}\n", "unknown lidar model 'VLP-99'"},
      {"calibration is a folder", left + "    calibration: folder\n", "is not a regular file"},
      {"calibration is a device", left + "    calibration: /dev/zero\n", "is not a regular file"},
      {"calibration missing", left + "    calibration: none.yaml\n", "not found"},
      {"calibration too large", left + "    calibration: huge.yaml\n", "the limit is 16777216"},
      {"calibration unparsable", left + "    calibration: garbage.yaml\n", "sensor 'left': "},
      {"bad IPv4 address", "model: VLP-16\n    source: {port: 2399, address: 192.168.1.300}\n",
       "'address' = '192.168.1.300' is not an IPv4 address"},
      {"bad multicast group", "model: VLP-16\n    source: {port: 2399, multicast_group: 10.0.0.1}\n",
       "is not a multicast address"},
      {"duplicate key", left + "    model: HDL-32E\n", "key 'model' appears twice"},
      {"same port, no addresses", "model: VLP-16\n    source: {port: 2368}\n",
       "sensors 'top' and 'left' both receive on port 2368 without distinct source addresses"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    expectRefusedByBoth(withLeft(c.replacement), c.message);
  }
  // The same address twice on one port is as ambiguous as none.
  {
    std::ofstream f(dir / "rig.yaml", std::ios::trunc);
    f << "sensors:\n"
         "  - {name: a, model: VLP-16, source: {port: 2368, address: 10.0.0.5}}\n"
         "  - {name: b, model: VLP-16, source: {port: 2368, address: 10.0.0.5}}\n"
         "roles: {mapping_lidar: a}\n";
  }
  expectRefusedByBoth(dir / "rig.yaml", "sensors 'a' and 'b' both receive on port 2368 from the same address 10.0.0.5");
}

// A huge rig file fails at once on its size, and a rig with too many sensors on their count.
TEST(TrustConfig, RigFileSizeAndSensorCountAreCapped) {
  TempDir dir;
  {
    std::ofstream f(dir / "rig.yaml");
    f << "sensors:\n";
    for (int i = 0; i < 65; ++i)
      f << "  - {name: s" << i << ", model: VLP-16, source: {port: " << 3000 + i << "}}\n";
    f << "roles: {mapping_lidar: s0}\n";
  }
  expectRefusedByBoth(dir / "rig.yaml", "'sensors' lists 65 sensors; the limit is 64");
  {
    std::ofstream f(dir / "big.yaml");
    const std::string sensor = "  - {name: s, model: VLP-16, source: {port: 3000}}\n";
    f << "sensors:\n";
    for (std::size_t bytes = 0; bytes < (50u << 20); bytes += sensor.size()) f << sensor;
  }
  const auto t0 = std::chrono::steady_clock::now();
  const auto big = runRigcal({"check-config", (dir / "big.yaml").string()});
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(big.exit_code, 3) << big.err;
  EXPECT_NE(big.err.find("the limit is 1048576"), std::string::npos) << big.err;
  EXPECT_LT(seconds, 5.0) << "fails fast";
}

// A folder (or a missing file) where a file is expected is the same mistake in every command: exit 4.
TEST(TrustConfig, AFolderWhereAFileIsExpectedIsExit4Everywhere) {
  TempDir dir;
  const auto rig = writeRig(dir);
  const std::string folder = dir.path().string(), out = (dir / "out").string();
  std::ofstream(dir / "p.csv") << "1000,0,0,0,0,1,0,0,0\n";
  const std::vector<std::vector<std::string>> commands = {
      {"check-config", folder},
      {"calibrate", "--config", folder, "--pcap", rig.string(), "--out", out},
      {"calibrate", "--config", rig.string(), "--pcap", folder, "--out", out},
      {"map", "--config", rig.string(), "--pcap", folder},
      {"map", "--config", folder, "--pcap", rig.string()},
      {"driver", "--config", rig.string(), "--sensor", "top", "--pcap", folder},
      {"decode", folder, "--sensor", "VLP-16", "--out", out},
      {"replay", folder, "--to", "127.0.0.1"},
      {"calibrate-pose", "--pcap", folder, "--poses", (dir / "p.csv").string(), "--model", "VLP-16"},
      {"compare", "--truth", folder, "--result", rig.string()},
  };
  for (const auto& args : commands) {
    const auto r = runRigcal(args);
    EXPECT_EQ(r.exit_code, 4) << args[0] << ' ' << args[1] << ' ' << args[2] << ": " << r.err;
    EXPECT_NE(r.err.find(folder + ": "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("is not a regular file"), std::string::npos) << r.err;
  }
}

// A poses CSV row with an absurd position or an impossible jump is refused with its line number.
TEST(TrustInputs, PosesWithAbsurdValuesAreRefusedWithTheLine) {
  TempDir dir;
  std::ofstream(dir / "x.pcap") << "x";
  const std::string header = "# timestamp_ns, index, px, py, pz, qw, qx, qy, qz\n";
  const std::string good = "1000000000,0,0,0,0,1,0,0,0\n1100000000,1,0.5,0,0,1,0,0,0\n";
  const auto run = [&](const std::string& row) {
    std::ofstream(dir / "poses.csv", std::ios::trunc) << header << good << row;
    return runRigcal({"calibrate-pose", "--pcap", (dir / "x.pcap").string(), "--poses",
                      (dir / "poses.csv").string(), "--model", "VLP-16"});
  };
  const auto huge = run("1200000000,2,1e300,0,0,1,0,0,0\n");
  EXPECT_EQ(huge.exit_code, 4) << huge.err;
  EXPECT_NE(huge.err.find("poses.csv:4: column 3 (px): '1e300' is beyond"), std::string::npos) << huge.err;
  const auto jump = run("1200000000,2,500,0,0,1,0,0,0\n");
  EXPECT_EQ(jump.exit_code, 4) << jump.err;
  EXPECT_NE(jump.err.find("poses.csv:4: position jumps 499.5 m in 0.1 s since line 3"), std::string::npos)
      << jump.err;
  EXPECT_NE(run("1200000000,2,inf,0,0,1,0,0,0\n").err.find("poses.csv:4:"), std::string::npos);
}

}  // namespace
}  // namespace rigcal::test
