#include "leglab/servo/servo_log_io.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include "leglab/app/input_error.h"
#include "leglab/app/program.h"

namespace leglab {
namespace {

namespace fs = std::filesystem;

const ServoLogDefaults kDefaults{.motor = "xl330", .kp = 400, .mass_kg = 0.49, .length_m = 0.1};

// Scratch files in a folder of this test's own (name and process id: ctest runs tests at once).
class ServoLogIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("leglab_servo_log_io_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return (dir_ / name).string();
  }

  // The message of the InputError that reading `path` throws, or "" if none; every message is
  // one line of at most 300 characters that names the file.
  static std::string ErrorOf(const std::string& path,
                             ServoLogFormat format = ServoLogFormat::kAuto) {
    try {
      ReadServoLog(path, format, kDefaults);
    } catch (const InputError& e) {
      std::string message = e.what();
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
      EXPECT_LE(message.size(), 300u) << message;
      EXPECT_NE(message.find(fs::path(path).filename().string()), std::string::npos) << message;
      return message;
    }
    return "";
  }
  std::string CsvError(const std::string& text) { return ErrorOf(Write("log.csv", text)); }
  std::string JsonError(const std::string& text) { return ErrorOf(Write("log.json", text)); }

  fs::path dir_;
};

// The message contains every one of `parts`.
#define EXPECT_MESSAGE(message, ...)                                                   \
  for (const char* part : {__VA_ARGS__}) {                                             \
    EXPECT_NE((message).find(part), std::string::npos) << part << " in " << (message); \
  }

double Deg(double rad) { return rad * 180.0 / std::numbers::pi; }

TEST_F(ServoLogIoTest, ReadsAShippedBamLog) {
  const std::string path = std::string(LEGLAB_SOURCE_DIR) +
                           "/data/servo_logs/feetech-sts3250/sin_sin_kp32_2024-10-26_12h23m27.json";
  const ServoLog log = ReadServoLog(path, ServoLogFormat::kAuto, kDefaults);
  EXPECT_EQ(log.file, path);
  EXPECT_EQ(log.motor, "sts3250");
  EXPECT_EQ(log.trajectory, "sin_sin");
  EXPECT_EQ(log.kp, 32.0);
  EXPECT_EQ(log.mass_kg, 1.13);
  EXPECT_EQ(log.length_m, 0.12);
  ASSERT_EQ(log.samples.size(), 286u);
  // The first entry's numbers, copied from the file.
  const ServoLogSample& first = log.samples.front();
  EXPECT_EQ(first.time_s, 0.013696789741516113);
  EXPECT_NEAR(first.request_deg, Deg(7.864772933845965e-06), 1e-15);
  EXPECT_NEAR(first.measured_deg, Deg(0.0015339807878856412), 1e-14);
  EXPECT_NEAR(first.measured_deg, 0.087890625, 1e-12);  // 1 step of 4096 a turn
  EXPECT_TRUE(first.torque_enabled);
  // The same file read as named, not by its extension.
  EXPECT_EQ(ReadServoLog(path, ServoLogFormat::kBamJson, {}).samples.size(), 286u);
}

TEST_F(ServoLogIoTest, ReadsEveryShippedLog) {
  int count = 0;
  for (const char* folder : {"dynamixel-xl330", "feetech-sts3250"}) {
    const fs::path dir = fs::path(LEGLAB_SOURCE_DIR) / "data/servo_logs" / folder;
    for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
      const ServoLog log = ReadServoLog(entry.path().string(), ServoLogFormat::kAuto, {});
      EXPECT_GT(log.samples.size(), 200u) << entry.path();
      EXPECT_EQ(log.motor, std::string(folder) == "feetech-sts3250" ? "sts3250" : "xl330");
      ++count;
    }
  }
  EXPECT_EQ(count, 16);
}

TEST_F(ServoLogIoTest, ReadsACsvWithoutTorqueColumn) {
  const ServoLog log =
      ReadServoLog(Write("up_down.csv",
                         "time_s,request_deg,measured_deg\r\n0,1.5,-2\r\n\r\n0.005,3,-1.25e1\r\n"),
                   ServoLogFormat::kAuto, kDefaults);
  EXPECT_EQ(log.trajectory, "up_down");
  EXPECT_EQ(log.motor, "xl330");
  EXPECT_EQ(log.kp, 400.0);
  EXPECT_EQ(log.mass_kg, 0.49);
  EXPECT_EQ(log.length_m, 0.1);
  ASSERT_EQ(log.samples.size(), 2u);
  EXPECT_EQ(log.samples[1].time_s, 0.005);
  EXPECT_EQ(log.samples[0].request_deg, 1.5);
  EXPECT_EQ(log.samples[1].measured_deg, -12.5);
  EXPECT_TRUE(log.samples[0].torque_enabled && log.samples[1].torque_enabled);
}

TEST_F(ServoLogIoTest, ReadsACsvWithTorqueColumn) {
  const ServoLog log = ReadServoLog(Write("drop.CSV",
                                          "time_s,request_deg,measured_deg,torque_enabled\n"
                                          "0,0,0,1\n0.25,10,1,1\n0.5,10,4,0"),
                                    ServoLogFormat::kAuto, kDefaults);
  ASSERT_EQ(log.samples.size(), 3u);
  EXPECT_TRUE(log.samples[1].torque_enabled);
  EXPECT_FALSE(log.samples[2].torque_enabled);
  EXPECT_EQ(log.samples[2].measured_deg, 4.0);
}

TEST_F(ServoLogIoTest, ReadsAMillionSamples) {
  std::string text = "time_s,request_deg,measured_deg,torque_enabled\n";
  for (int i = 0; i < 1'000'000; ++i) text += std::to_string(i) + ".5,-12.25,3.125,1\n";
  const ServoLog log = ReadServoLog(Write("long.csv", text), ServoLogFormat::kAuto, kDefaults);
  ASSERT_EQ(log.samples.size(), 1'000'000u);
  EXPECT_EQ(log.samples.back().time_s, 999'999.5);
}

TEST_F(ServoLogIoTest, FilesThatAreNotLogs) {
  EXPECT_MESSAGE(ErrorOf((dir_ / "missing.csv").string()), "no such file");
  fs::create_directories(dir_ / "folder.json");
  EXPECT_MESSAGE(ErrorOf((dir_ / "folder.json").string()), "is a folder");
  EXPECT_MESSAGE(ErrorOf(Write("empty.csv", "")), "is empty");
  EXPECT_MESSAGE(ErrorOf(Write("log.txt", "time_s,request_deg,measured_deg\n0,0,0\n1,0,0\n")),
                 "extension '.txt'", ".csv or .json");
  // Refused by its size, before it is read: a sparse file one byte over the limit.
  const std::string big = Write("big.json", "");
  fs::resize_file(big, kMaxServoLogBytes + 1);
  EXPECT_MESSAGE(ErrorOf(big), "67108865 bytes", "64 MiB");
}

TEST_F(ServoLogIoTest, BadCsvHeaders) {
  EXPECT_MESSAGE(CsvError("\xEF\xBB\xBFtime_s,request_deg,measured_deg\n0,0,0\n1,0,0\n"),
                 "header must be", "got '\\ufefftime_s,");
  EXPECT_MESSAGE(CsvError("time,request,measured\n0,0,0\n1,0,0\n"), "got 'time,request,measured'");
  EXPECT_MESSAGE(CsvError("time_s,request_deg,measured_deg\t\n0,0,0\n"), "measured_deg\\t'");
}

TEST_F(ServoLogIoTest, BadCsvRows) {
  const std::string h = "time_s,request_deg,measured_deg\n";
  const std::string ht = "time_s,request_deg,measured_deg,torque_enabled\n";
  EXPECT_MESSAGE(CsvError(h + "0,0,0\n1,0\n"), "row 2 has 2 columns, expected 3");
  EXPECT_MESSAGE(CsvError(h + "0,0,0,\n"), "row 1 has 4 columns, expected 3");
  EXPECT_MESSAGE(CsvError(h + "0,0,0\n\n1,abc,0\n"), "row 3, request_deg: 'abc' is not a decimal");
  EXPECT_MESSAGE(CsvError(h + "0,0,0\n1,0,+2\n"), "row 2, measured_deg: '+2' is not a decimal");
  EXPECT_MESSAGE(CsvError(h + "0, 1,0\n"), "row 1, request_deg: ' 1'");
  EXPECT_MESSAGE(CsvError(h + "0,,0\n"), "row 1, request_deg: '' is not");
  EXPECT_MESSAGE(CsvError(h + "0,0,0\nnan,0,0\n"), "row 2, time_s: 'nan' is not finite");
  EXPECT_MESSAGE(CsvError(h + "0,inf,0\n"), "row 1, request_deg: 'inf' is not finite");
  EXPECT_MESSAGE(CsvError(ht + "0,0,0,1\n1,0,0,yes\n"),
                 "row 2, torque_enabled: 'yes' is not 0 or 1");
  // A long cell is cut to 40 characters.
  const std::string message = CsvError(h + "0," + std::string(500, '7') + "x,0\n");
  EXPECT_MESSAGE(message, "row 1, request_deg: '7777777777", "...'");
}

TEST_F(ServoLogIoTest, BadCsvTimesAndSamples) {
  const std::string h = "time_s,request_deg,measured_deg\n";
  const std::string ht = "time_s,request_deg,measured_deg,torque_enabled\n";
  EXPECT_MESSAGE(CsvError(h + "0,0,0\n0.5,0,0\n0.5,0,0\n"),
                 "row 3, time_s = 0.5 is not after row 2's 0.5");
  EXPECT_MESSAGE(CsvError(h + "0,0,0\n1,0,0\n\n0.5,0,0\n"),
                 "row 4, time_s = 0.5 is not after row 2's 1");
  EXPECT_MESSAGE(CsvError(h + "0,0,0\n"), "has 1 samples, at least 2");
  EXPECT_MESSAGE(CsvError(h), "has 0 samples, at least 2");
  EXPECT_MESSAGE(CsvError(ht + "0,0,0,0\n1,0,0,0\n"), "torque is off in every sample");
}

TEST_F(ServoLogIoTest, TooManyCsvSamples) {
  std::string text = "time_s,request_deg,measured_deg\n";
  for (size_t i = 0; i <= kMaxServoLogSamples; ++i) text += std::to_string(i) + ",0,0\n";
  EXPECT_MESSAGE(CsvError(text), "row 2000001: more than 2000000 samples");
}

TEST_F(ServoLogIoTest, BadCsvDefaults) {
  const std::string path = Write("log.csv", "time_s,request_deg,measured_deg\n0,0,0\n1,0,0\n");
  for (const ServoLogDefaults& bad :
       {ServoLogDefaults{.kp = -1}, ServoLogDefaults{.mass_kg = std::nan("")},
        ServoLogDefaults{.length_m = -0.5}}) {
    try {
      ReadServoLog(path, ServoLogFormat::kCsv, bad);
      ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
      EXPECT_MESSAGE(std::string(e.what()), "log.csv", "(given for a CSV log) must be in [0, ");
    }
  }
}

// A BAM log with `top` as its other top-level fields and `entries` as its entries.
std::string Bam(
    const std::string& entries,
    const std::string& top =
        R"("mass": 0.49, "length": 0.1, "kp": 100, "motor": "xl330", "trajectory": "sin_sin")") {
  return "{" + top + R"(, "entries": [)" + entries + "]}";
}
const std::string kEntry0 =
    R"({"timestamp": 0.0, "goal_position": 0.0, "position": 0.0, "torque_enable": true})";
const std::string kEntry1 =
    R"({"timestamp": 0.01, "goal_position": 0.1, "position": 0.05, "torque_enable": true, "speed": 1})";

TEST_F(ServoLogIoTest, AMinimalBamLogAndItsRadians) {
  const ServoLog log = ReadServoLog(Write("min.json", Bam(kEntry0 + "," + kEntry1)),
                                    ServoLogFormat::kAuto, kDefaults);
  ASSERT_EQ(log.samples.size(), 2u);
  EXPECT_NEAR(log.samples[1].request_deg, Deg(0.1), 1e-12);
  EXPECT_NEAR(log.samples[1].measured_deg, Deg(0.05), 1e-12);
  EXPECT_EQ(log.kp, 100.0);
}

TEST_F(ServoLogIoTest, BadBamLogs) {
  const std::string both = kEntry0 + "," + kEntry1;
  EXPECT_MESSAGE(JsonError("{\"mass\": "), "is not valid JSON");
  EXPECT_MESSAGE(JsonError("[1, 2]"), "expected one JSON object, got array");
  EXPECT_MESSAGE(
      JsonError(Bam(both, R"("mass": 0.49, "length": 0.1, "kp": 100, "motor": "xl330")")),
      "no field 'trajectory'");
  EXPECT_MESSAGE(
      JsonError(
          Bam(both,
              R"("mass": "heavy", "length": 0.1, "kp": 100, "motor": "xl330", "trajectory": "t")")),
      "mass: expected a number, got string");
  EXPECT_MESSAGE(
      JsonError(Bam(
          both, R"("mass": 0.49, "length": -0.1, "kp": 100, "motor": "xl330", "trajectory": "t")")),
      "length must be in [0, 10] m, got -0.1");
  EXPECT_MESSAGE(
      JsonError(
          Bam(both,
              R"("mass": 0.49, "length": 0.1, "kp": 1e999, "motor": "xl330", "trajectory": "t")")),
      "is not valid JSON", "number overflow");
  EXPECT_MESSAGE(
      JsonError(Bam(
          both, R"("mass": 0.49, "length": 0.1, "kp": -3, "motor": "xl330", "trajectory": "t")")),
      "kp must be in [0, 1000000], got -3");
  EXPECT_MESSAGE(
      JsonError(
          R"({"mass": 0.49, "length": 0.1, "kp": 1, "motor": "m", "trajectory": "t", "entries": {}})"),
      "entries: expected an array, got object");
  EXPECT_MESSAGE(JsonError(Bam(kEntry0 + ", 7")), "entries[1]: expected an object, got number");
  EXPECT_MESSAGE(
      JsonError(Bam(kEntry0 + R"(, {"timestamp": 1, "goal_position": 0, "torque_enable": true})")),
      "entries[1] has no field 'position'");
  EXPECT_MESSAGE(
      JsonError(
          Bam(kEntry0 +
              R"(, {"timestamp": "1", "goal_position": 0, "position": 0, "torque_enable": true})")),
      "entries[1].timestamp: expected a number, got string");
  EXPECT_MESSAGE(
      JsonError(
          Bam(kEntry0 +
              R"(, {"timestamp": 1, "goal_position": 0, "position": 0, "torque_enable": 1})")),
      "entries[1].torque_enable: expected true or false, got number");
  EXPECT_MESSAGE(JsonError(Bam(both + "," + kEntry1)),
                 "entries[2].timestamp = 0.01 is not after entries[1]'s 0.01");
  EXPECT_MESSAGE(JsonError(Bam(kEntry1 + "," + kEntry0)), "entries[1].timestamp = 0 is not after");
  EXPECT_MESSAGE(JsonError(Bam(kEntry0)), "has 1 samples, at least 2");
  EXPECT_MESSAGE(
      JsonError(Bam(
          R"({"timestamp": 0, "goal_position": 0, "position": 0, "torque_enable": false}, {"timestamp": 1, "goal_position": 0, "position": 0, "torque_enable": false})")),
      "torque is off in every sample");
}

}  // namespace
// A number a servo cannot have is refused as the file is read, naming where it is: an angle
// beyond +-100000 deg (1e300 rad, a request of 1e308 deg), a gain, mass or arm beyond its
// bound. Just inside each bound the log reads.
// Names go into log_fit.md and file names: a newline or a name too long is refused when the
// log is read, naming the file and the field; 100 bytes are taken.
TEST_F(ServoLogIoTest, MotorAndTrajectoryNamesAreShortAndOnOneLine) {
  const std::string both = kEntry0 + "," + kEntry1;
  const auto fields = [](const std::string& motor, const std::string& trajectory) {
    return R"("mass": 0.49, "length": 0.1, "kp": 100, "motor": ")" + motor +
           R"(", "trajectory": ")" + trajectory + "\"";
  };
  EXPECT_MESSAGE(JsonError(Bam(both, fields("xl\\n330", "t"))),
                 "motor 'xl\\n330' holds a control character");
  EXPECT_MESSAGE(JsonError(Bam(both, fields("xl330", "a\\rb"))), "trajectory", "control character");
  EXPECT_MESSAGE(JsonError(Bam(both, fields(std::string(101, 'm'), "t"))),
                 "motor is 101 bytes long, over the limit of 100");
  EXPECT_EQ(JsonError(Bam(both, fields(std::string(100, 'm'), "t"))), "");
  ServoLog given = ReadServoLog(Write("ok.json", Bam(both, fields("xl330", "t"))),
                                ServoLogFormat::kAuto, kDefaults);
  given.motor = "two\nlines";
  EXPECT_THROW(CheckServoLog(given), InputError);
}

TEST(MarkdownText, EscapesWhatWouldEndACellStartMarkupOrBreakALine) {
  EXPECT_EQ(MarkdownText("sin_sin"), "sin_sin");
  EXPECT_EQ(MarkdownText("a|b<c>\nd\x7f\xEF\xBB\xBF"), "a\\|b&lt;c>\\nd\\x7f\\ufeff");
}

TEST_F(ServoLogIoTest, PhysicallyImpossibleValuesAreRefusedWhereTheyAre) {
  const std::string h = "time_s,request_deg,measured_deg\n";
  EXPECT_MESSAGE(CsvError(h + "0,0,0\n1,1e308,0\n"),
                 "row 2, request_deg must be in [-100000, 100000] deg, got 1e+308");
  EXPECT_MESSAGE(CsvError(h + "0,0,-100000.5\n1,0,0\n"), "row 1, measured_deg");
  EXPECT_EQ(CsvError(h + "0,0,-100000\n1,100000,0\n"), "");
  EXPECT_MESSAGE(
      JsonError(Bam(kEntry0 + R"(, {"timestamp": 1, "goal_position": 0, "position": 1e300,
                                    "torque_enable": true})")),
      "entries[1].position must be in [-100000, 100000] deg, got 5.7");
  EXPECT_MESSAGE(
      JsonError(Bam(kEntry0 + "," + kEntry1,
                    R"("mass": 1e200, "length": 0.1, "kp": 100, "motor": "m", "trajectory": "t")")),
      "mass must be in [0, 1000] kg, got 1e+200");
  EXPECT_MESSAGE(
      JsonError(Bam(kEntry0 + "," + kEntry1,
                    R"("mass": 0.5, "length": 10.5, "kp": 100, "motor": "m", "trajectory": "t")")),
      "length must be in [0, 10] m, got 10.5");
  EXPECT_MESSAGE(
      JsonError(Bam(kEntry0 + "," + kEntry1,
                    R"("mass": 0.5, "length": 0.1, "kp": 2e6, "motor": "m", "trajectory": "t")")),
      "kp must be in [0, 1000000], got 2e+06");
}

}  // namespace leglab
