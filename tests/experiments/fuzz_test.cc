// A seeded random mutator over the three readers of user files: the config loader (YAML,
// extends:, --set), the desired-motion CSV reader and the URDF loader; and over the robot files
// as far as the plant they build: the shipped leg.urdf and robot.yaml mutated in their
// structure and numbers, loaded, built into the simulated plant and ticked. Each execution mutates
// a seed input (the shipped files and a few hostile ones) and feeds it to the reader; the
// contract is that the reader either accepts it with every number it returns finite, or
// throws one of the bad-input exceptions the programs turn into exit status 2 (InputError,
// std::invalid_argument, std::domain_error). Anything else (another exception, a crash, a
// sanitizer report in the asan build) is a finding: the input is saved under
// $TMPDIR/leglab_fuzz_findings/ and should become a file in tests/experiments/fuzz_regressions/,
// which every run replays first.
//
// Each harness gets a fixed time rather than a fixed count, so that a reader that becomes slower
// costs no more suite time: LEGLAB_FUZZ_SECONDS per reader (default 2, so that the suite stays
// quick; .ci/run gives the release build 30 and the sanitizer build 15). The inputs are one
// seeded sequence whatever the budget, so a longer budget runs a longer prefix of the same
// inputs. LEGLAB_FUZZ_EXECUTIONS, when set, runs exactly that many inputs instead (to replay a
// run's count); LEGLAB_FUZZ_SEED sets the seed (default 1: the same inputs every run). Each test
// prints its executions, findings and inputs per second.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "leglab/core/plant.h"
#include "leglab/experiments/config.h"
#include "leglab/experiments/rig.h"
#include "leglab/experiments/robot.h"

namespace leglab::experiments {
namespace {

namespace fs = std::filesystem;

long EnvLong(const char* name, long fallback) {
  const char* value = std::getenv(name);
  return value != nullptr ? std::strtol(value, nullptr, 10) : fallback;
}

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void WriteFile(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// Byte- and token-level mutations of a seed input, drawn from one seeded generator.
class Mutator {
 public:
  Mutator(std::uint64_t seed, std::vector<std::string> dictionary)
      : random_(seed), dictionary_(std::move(dictionary)) {}

  std::string Mutate(std::string text) {
    const int mutations = Pick(1, 6);
    for (int m = 0; m < mutations; ++m) {
      const size_t at =
          text.empty() ? 0 : static_cast<size_t>(Pick(0, static_cast<int>(text.size())));
      switch (Pick(0, 6)) {
        case 0:  // a token from the dictionary
          text.insert(at, dictionary_[Pick(0, static_cast<int>(dictionary_.size()) - 1)]);
          break;
        case 1:  // a token replacing a short run of bytes
          text.replace(at, Pick(0, 8),
                       dictionary_[Pick(0, static_cast<int>(dictionary_.size()) - 1)]);
          break;
        case 2:  // a random byte
          text.insert(at, 1, static_cast<char>(Pick(0, 255)));
          break;
        case 3:  // a deletion
          text.erase(at, Pick(1, 16));
          break;
        case 4: {  // a chunk copied elsewhere
          const size_t from = text.empty() ? 0 : Pick(0, static_cast<int>(text.size()) - 1);
          text.insert(at, text.substr(from, Pick(1, 64)));
          break;
        }
        case 5:  // a digit changed (numbers are most of these files)
          for (size_t i = at; i < text.size(); ++i) {
            if (std::isdigit(static_cast<unsigned char>(text[i]))) {
              text[i] = static_cast<char>('0' + Pick(0, 9));
              break;
            }
          }
          break;
        default:  // a line dropped
          if (const size_t end = text.find('\n', at); end != std::string::npos) {
            const size_t start = text.rfind('\n', at);
            text.erase(start == std::string::npos ? 0 : start,
                       end - (start == std::string::npos ? 0 : start));
          }
          break;
      }
      if (text.size() > 20000) text.resize(20000);
    }
    return text;
  }

  int Pick(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(random_); }

 private:
  std::mt19937_64 random_;
  std::vector<std::string> dictionary_;
};

// Numbers a hostile user tries.
const std::vector<std::string> kNumbers = {"0",
                                           "-1",
                                           "1e300",
                                           "-1e300",
                                           "1e-300",
                                           ".nan",
                                           ".inf",
                                           "-.inf",
                                           "nan",
                                           "inf",
                                           "2147483647",
                                           "2147483648",
                                           "-2147483648",
                                           "9223372036854775807",
                                           "99999999999999999999",
                                           "0x7",
                                           "1.5",
                                           "4",
                                           "88",
                                           "1000000",
                                           "+5",
                                           "07",
                                           ""};

struct Runner {
  const char* reader;
  std::vector<std::string> seeds;
  std::vector<std::string> dictionary;
  fs::path file;  // where each input is written for the reader
  // Reads `file`; returns normally when accepted (after checking its numbers are finite),
  // throws when refused.
  std::function<void()> read;
  // When set, makes each input from a seed instead of the byte mutator (same generator seed).
  std::function<std::string(const std::string&, std::uint64_t)> mutate = nullptr;
};

double EnvDouble(const char* name, double fallback) {
  const char* value = std::getenv(name);
  return value != nullptr ? std::strtod(value, nullptr) : fallback;
}

// Runs the replayed regressions, then mutated inputs for LEGLAB_FUZZ_SECONDS (or exactly
// LEGLAB_FUZZ_EXECUTIONS of them when that is set); reports findings as failures.
void Fuzz(Runner& runner) {
  const fs::path findings_dir = fs::temp_directory_path() / "leglab_fuzz_findings";
  const bool counted = std::getenv("LEGLAB_FUZZ_EXECUTIONS") != nullptr;
  const long max_executions = counted ? EnvLong("LEGLAB_FUZZ_EXECUTIONS", 0) : -1;
  const double budget_s = EnvDouble("LEGLAB_FUZZ_SECONDS", 2.0);
  Mutator mutator(static_cast<std::uint64_t>(EnvLong("LEGLAB_FUZZ_SEED", 1)), [&] {
    std::vector<std::string> d = runner.dictionary;
    d.insert(d.end(), kNumbers.begin(), kNumbers.end());
    return d;
  }());
  std::vector<std::string> inputs;
  // The regressions first: every finding so far, replayed as is.
  const fs::path regressions = fs::path(LEGLAB_SOURCE_DIR) / "tests/experiments/fuzz_regressions";
  for (const auto& entry : fs::directory_iterator(regressions)) {
    if (entry.path().filename().string().rfind(std::string(runner.reader) + "_", 0) == 0) {
      inputs.push_back(ReadFile(entry.path()));
    }
  }
  const size_t replayed = inputs.size();
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  long accepted = 0, refused = 0, found = 0;
  const auto more = [&](long i) {
    if (i < static_cast<long>(replayed)) return true;
    if (counted) return i < max_executions + static_cast<long>(replayed);
    return std::chrono::duration<double>(Clock::now() - start).count() < budget_s;
  };
  long i = 0;
  for (; more(i); ++i) {
    const std::string input =
        i < static_cast<long>(replayed) ? inputs[i]
        : runner.mutate
            ? runner.mutate(
                  runner.seeds[mutator.Pick(0, static_cast<int>(runner.seeds.size()) - 1)],
                  static_cast<std::uint64_t>(i))
            : mutator.Mutate(
                  runner.seeds[mutator.Pick(0, static_cast<int>(runner.seeds.size()) - 1)]);
    WriteFile(runner.file, input);
    std::string problem;
    try {
      runner.read();
      ++accepted;
    } catch (const InputError&) {
      ++refused;
    } catch (const std::invalid_argument&) {
      ++refused;
    } catch (const std::domain_error&) {
      ++refused;
    } catch (const std::exception& e) {
      problem = std::string("escaped: ") + e.what();
    } catch (...) {
      problem = "escaped: an unknown exception";
    }
    if (!problem.empty()) {
      ++found;
      fs::create_directories(findings_dir);
      const fs::path saved =
          findings_dir / (std::string(runner.reader) + "_" + std::to_string(i) + ".txt");
      WriteFile(saved, input);
      ADD_FAILURE() << runner.reader << " execution " << i << ": " << problem << " (input saved in "
                    << saved << ")";
      if (found >= 5) {
        ++i;  // this input ran
        break;
      }
    }
  }
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  const long executions = i - static_cast<long>(replayed);
  std::printf(
      "fuzz %s: %ld executions in %.1f s (+%zu regressions replayed), %ld accepted, %ld refused, "
      "%ld findings, %.0f inputs/s\n",
      runner.reader, executions, seconds, replayed, accepted, refused, found,
      static_cast<double>(i) / seconds);
  // A budget too short for a single mutated input would check nothing.
  EXPECT_GT(executions, 0) << runner.reader << ": no mutated input ran";
}

void ExpectFinite(double v, const char* what) {
  if (!std::isfinite(v)) throw std::logic_error(std::string("accepted a non-finite ") + what);
}

class FuzzTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // In memory where there is a tmpfs: every execution writes its input.
    const fs::path base =
        fs::is_directory("/dev/shm") ? fs::path("/dev/shm") : fs::temp_directory_path();
    dir_ = base / ("leglab_fuzz_" +
                   std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

const fs::path kSource = LEGLAB_SOURCE_DIR;

TEST_F(FuzzTest, ConfigReader) {
  // The shipped files name the robot `ers210a`, found beside the test program (DataDir()).
  std::vector<std::string> seeds;
  for (const char* name :
       {"identify.yaml", "track.yaml", "track_hind.yaml", "controller_ilc.yaml"}) {
    seeds.push_back(ReadFile(kSource / "experiments/configs" / name));
  }
  seeds.push_back(ReadFile(kSource / "robots/ers210a/robot.yaml"));
  seeds.push_back("a: &a [1, 1]\nb: &b [*a, *a, *a, *a]\nc: &c [*b, *b, *b, *b]\nidentify: *c\n");
  seeds.push_back("extends: exp.yaml\nsteps: 3\n");
  seeds.push_back(
      "servo: {delay_ms: 40, delay_ms: 48}\nmodel: {v_max_deg_per_tick: 2.5, "
      "theta0_deg: 7, lag_ticks: 4, accel_ticks: 6}\n");
  Runner runner{"config",
                seeds,
                {"\n",
                 ": ",
                 "- ",
                 "[",
                 "]",
                 "{",
                 "}",
                 ",",
                 "&a ",
                 "*a",
                 "<<: *a\n",
                 "!!str ",
                 "extends: ",
                 "robot: ",
                 "servo:\n  ",
                 "identify:\n  ",
                 "controller:\n  ",
                 "model: ",
                 "desired:\n  csv: ",
                 "steps: ",
                 "warmup_steps: ",
                 "t_step_ticks: ",
                 "theta_test_deg: ",
                 "lag_range_ticks: ",
                 "seed: ",
                 "plant: model\n",
                 "? ",
                 "|\n",
                 "'",
                 "\"",
                 "#",
                 "\t",
                 "ers210a_hind",
                 "../../",
                 "~"},
                dir_ / "exp.yaml",
                {}};
  runner.read = [&] {
    const ExperimentConfig c = LoadExperimentConfig(runner.file.string());
    for (const double v :
         {c.sim.physics_dt_ms, c.sim.servo.delay_ms, c.sim.servo.max_speed_deg_s,
          c.sim.servo.gain_per_s, c.sim.servo.damping, c.sim.servo.smoothing_ms,
          c.sim.servo.max_torque_nm, c.sim.sensor.noise_deg, c.plant_model.v_max_deg_per_tick,
          c.plant_model.theta0_deg, c.track.locus.shape.length_mm, c.track.locus.shape.height_mm,
          c.track.locus.shape.ground_fraction, c.track.locus.forward_mm, c.track.locus.outward_mm,
          c.track.locus.ground_below_shoulder_mm}) {
      ExpectFinite(v, "config value");
    }
    for (const double v : c.identify.theta_test_deg) ExpectFinite(v, "theta_test_deg");
    for (const double v : c.identify.hold_deg) ExpectFinite(v, "hold_deg");
    if (c.model) {
      ExpectFinite(c.model->v_max_deg_per_tick, "model.v_max_deg_per_tick");
      ExpectFinite(c.model->theta0_deg, "model.theta0_deg");
    }
    if (c.planned_ticks <= 0 || c.planned_ticks > kMaxTotalTicks) {
      throw std::logic_error("accepted a run of " + std::to_string(c.planned_ticks) + " ticks");
    }
  };
  Fuzz(runner);
}

TEST_F(FuzzTest, DesiredCsvReader) {
  const Robot robot = LoadRobot((kSource / "robots/ers210a/leg.urdf").string());
  std::ostringstream csv;
  csv << "tick,rotator_deg,abductor_deg,knee_deg\n";
  for (int t = 0; t < 8; ++t) {
    csv << t << "," << 10 + 20 * std::sin(t) << ",5," << 60 + 15 * std::cos(t) << "\n";
  }
  Runner runner{"csv",
                {csv.str(), "tick,rotator_deg,abductor_deg,knee_deg\r\n0,1,2,3\r\n"},
                {",", "\n", "\r\n", "\r", "-", ".", "e", "e-", "e+400", "0x", "nan", "inf", " ",
                 "\"", "tick", "_deg", "1,2,3,4\n"},
                dir_ / "desired.csv",
                {}};
  runner.read = [&] {
    TrackConfig track;
    track.desired_csv = runner.file.string();
    track.t_step_ticks = 8;
    const DesiredMotion d = LoadDesiredMotion(track, robot.geometry);
    for (const LegAngles& q : d.angles_deg) {
      for (const double v : q) ExpectFinite(v, "angle");
    }
    for (const Eigen::Vector3d& p : d.foot_mm) {
      if (!p.allFinite()) throw std::logic_error("accepted a non-finite foot position");
    }
  };
  Fuzz(runner);
}

TEST_F(FuzzTest, UrdfLoader) {
  Runner runner{"urdf",
                {ReadFile(kSource / "robots/ers210a/leg.urdf"),
                 ReadFile(kSource / "robots/ers210a_hind/leg.urdf")},
                {"<",        ">",         "/>",         "</joint>",      "<link name=\"x\"/>",
                 "<joint",   "xyz=\"",    "rpy=\"",     "axis",          "limit",
                 "lower=\"", "upper=\"",  "effort=\"",  "mass value=\"", "\"",
                 " ",        "nan",       "inf",        "1e308",         "-0",
                 "revolute", "fixed",     "continuous", "foot",          "<!--",
                 "-->",      "<![CDATA[", "&amp;",      "&#0;"},
                dir_ / "leg.urdf",
                {}};
  runner.read = [&] {
    const Robot r = LoadRobot(runner.file.string());
    const LegGeometry& g = r.geometry;
    if (!g.shoulder_mm.allFinite() || !g.upper_leg_mm.allFinite() || !g.lower_leg_mm.allFinite()) {
      throw std::logic_error("accepted a non-finite segment");
    }
    for (const JointLimits& l : g.limits) {
      ExpectFinite(l.lower_rad, "limit");
      ExpectFinite(l.upper_rad, "limit");
    }
  };
  Fuzz(runner);
}

// Structural mutations of a robot file (a URDF or a robot.yaml), drawn from a generator seeded
// by the run's seed and the execution: a number scaled by a huge or tiny factor, its sign
// flipped or replaced by an extreme value, an attribute, a line or an element (an XML element
// or a YAML block) deleted or duplicated, the text cut short.
class StructureMutator {
 public:
  StructureMutator(std::uint64_t seed, std::uint64_t execution)
      : random_(seed * 0x9E3779B97F4A7C15ULL + execution) {}

  std::string Mutate(std::string text) {
    const int mutations = Pick(1, 3);
    for (int m = 0; m < mutations && !text.empty(); ++m) {
      switch (Pick(0, 9)) {
        case 0:
        case 1:
        case 2:
        case 3:
          MutateNumber(text);
          break;
        case 4:
          MutateAttribute(text, Pick(0, 1) == 0);
          break;
        case 5:
          MutateLine(text, Pick(0, 1) == 0);
          break;
        case 6:
        case 7:
          MutateBlock(text, Pick(0, 1) == 0);
          break;
        case 8:
          text.resize(Pick(0, static_cast<int>(text.size())));
          break;
        default:  // two numbers swapped for each other's extreme
          MutateNumber(text);
          MutateNumber(text);
          break;
      }
    }
    return text;
  }

 private:
  int Pick(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(random_); }

  // Where the numbers are: [begin, end) of each run of digits with its sign, point and exponent.
  static std::vector<std::pair<size_t, size_t>> Numbers(const std::string& text) {
    std::vector<std::pair<size_t, size_t>> found;
    auto digit = [&](size_t i) {
      return i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]));
    };
    for (size_t i = 0; i < text.size();) {
      if (!digit(i) && !(text[i] == '.' && digit(i + 1))) {
        ++i;
        continue;
      }
      size_t begin = i;
      if (begin > 0 && text[begin - 1] == '-') --begin;
      while (digit(i) || text[i] == '.') ++i;
      if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
        size_t j = i + 1;
        if (j < text.size() && (text[j] == '-' || text[j] == '+')) ++j;
        if (digit(j)) {
          i = j;
          while (digit(i)) ++i;
        }
      }
      found.emplace_back(begin, i);
    }
    return found;
  }

  void MutateNumber(std::string& text) {
    const auto numbers = Numbers(text);
    if (numbers.empty()) return;
    const auto [begin, end] = numbers[Pick(0, static_cast<int>(numbers.size()) - 1)];
    const double value = std::strtod(text.substr(begin, end - begin).c_str(), nullptr);
    static const char* const kExtremes[] = {"nan",   "NaN",    ".nan",   "inf", "-inf", ".inf",
                                            "1e308", "-1e308", "1e-308", "0",   "-0",   "1e400"};
    std::string replacement;
    char buffer[64];
    switch (Pick(0, 3)) {
      case 0: {  // scaled by a huge or tiny factor
        static const double kFactors[] = {1e-300, 1e-12, 1e-6, 1e-3, 1e3, 1e6, 1e12, 1e300};
        std::snprintf(buffer, sizeof buffer, "%.17g", value * kFactors[Pick(0, 7)]);
        replacement = buffer;
        break;
      }
      case 1:  // the sign flipped
        std::snprintf(buffer, sizeof buffer, "%.17g", -value);
        replacement = buffer;
        break;
      case 2:  // nudged (a limit pair crossed, a multiple of 8 missed)
        std::snprintf(buffer, sizeof buffer, "%.17g", value * (1 + 0.5 * (Pick(0, 1) * 2 - 1)));
        replacement = buffer;
        break;
      default:
        replacement = kExtremes[Pick(0, 11)];
        break;
    }
    text.replace(begin, end - begin, replacement);
  }

  // An XML attribute ` name="value"` deleted or written twice.
  void MutateAttribute(std::string& text, bool remove) {
    std::vector<size_t> quotes;  // the `="` of each attribute
    for (size_t at = text.find("=\""); at != std::string::npos; at = text.find("=\"", at + 2)) {
      quotes.push_back(at);
    }
    if (quotes.empty()) return MutateLine(text, remove);
    const size_t equals = quotes[Pick(0, static_cast<int>(quotes.size()) - 1)];
    const size_t begin = text.rfind(' ', equals);
    const size_t close = text.find('"', equals + 2);
    if (begin == std::string::npos || close == std::string::npos) return;
    const std::string attribute = text.substr(begin, close + 1 - begin);
    if (remove) {
      text.erase(begin, attribute.size());
    } else {
      text.insert(close + 1, attribute);
    }
  }

  // The line span [begin, end) (with its newline) of a randomly picked line.
  std::pair<size_t, size_t> PickLine(const std::string& text) {
    const size_t at = Pick(0, static_cast<int>(text.size()) - 1);
    const size_t newline = text.rfind('\n', at);
    const size_t begin = newline == std::string::npos ? 0 : newline + 1;
    const size_t end = text.find('\n', at);
    return {begin, end == std::string::npos ? text.size() : end + 1};
  }

  void MutateLine(std::string& text, bool remove) {
    const auto [begin, end] = PickLine(text);
    if (remove) {
      text.erase(begin, end - begin);
    } else {
      text.insert(end, text.substr(begin, end - begin));
    }
  }

  // An element (a `<tag` line through its `</tag>` or its `/>`) or a YAML block (a line and
  // the more-indented lines under it) deleted or written twice.
  void MutateBlock(std::string& text, bool remove) {
    auto [begin, end] = PickLine(text);
    const std::string line = text.substr(begin, end - begin);
    const size_t indent = line.find_first_not_of(' ');
    if (indent == std::string::npos) return;
    if (line[indent] == '<' && indent + 1 < line.size() &&
        std::isalpha(static_cast<unsigned char>(line[indent + 1])) != 0) {
      const size_t name_end = line.find_first_of(" >/\n", indent + 1);
      const std::string name = line.substr(indent + 1, name_end - indent - 1);
      if (line.find("/>") == std::string::npos) {
        const size_t close = text.find("</" + name + ">", begin);
        if (close != std::string::npos) {
          const size_t newline = text.find('\n', close);
          end = newline == std::string::npos ? text.size() : newline + 1;
        }
      }
    } else {
      while (end < text.size()) {
        const size_t next = text.find('\n', end);
        const size_t next_end = next == std::string::npos ? text.size() : next + 1;
        const size_t next_indent = text.find_first_not_of(' ', end);
        if (next_indent >= next_end - 1 || next_indent - end <= indent) break;
        end = next_end;
      }
    }
    if (remove) {
      text.erase(begin, end - begin);
    } else {
      text.insert(end, text.substr(begin, end - begin));
    }
  }

  std::mt19937_64 random_;
};

// `text` without its XML comments: the mutations then fall on the content.
std::string WithoutXmlComments(std::string text) {
  for (size_t at = text.find("<!--"); at != std::string::npos; at = text.find("<!--", at)) {
    const size_t end = text.find("-->", at);
    text.erase(at, end == std::string::npos ? std::string::npos : end + 3 - at);
  }
  return text;
}

// `text` without its YAML comment lines.
std::string WithoutYamlComments(const std::string& text) {
  std::istringstream in(text);
  std::string out;
  for (std::string line; std::getline(in, line);) {
    const size_t first = line.find_first_not_of(' ');
    if (first != std::string::npos && line[first] != '#') out += line + "\n";
  }
  return out;
}

// The experiment `config_path` names, loaded with its robot, built into a plant and ticked a few
// times towards a pose away from rest: every reading finite, or a bad-input exception.
void LoadBuildAndTick(const fs::path& config_path) {
  const ExperimentConfig config = LoadExperimentConfig(config_path.string());
  const Robot robot = LoadRobot(config.sim.urdf_path);
  const std::unique_ptr<Plant> plant = MakePlant(config, robot);
  for (int tick = 0; tick < 4; ++tick) {
    const PlantReading& r = plant->Tick(LegAngles{30, 20, 60});
    for (int j = 0; j < kLegJoints; ++j) {
      ExpectFinite(r.measured_deg[j], "measured angle");
      ExpectFinite(r.true_deg[j], "true angle");
    }
  }
}

std::function<std::string(const std::string&, std::uint64_t)> StructureMutations() {
  return [](const std::string& seed, std::uint64_t execution) {
    return StructureMutator(static_cast<std::uint64_t>(EnvLong("LEGLAB_FUZZ_SEED", 1)), execution)
        .Mutate(seed);
  };
}

// The shipped robot.yaml with its URDF beside it, and an experiment naming it by path.
void WriteRobotFiles(const fs::path& dir) {
  fs::copy_file(kSource / "robots/ers210a/leg.urdf", dir / "leg.urdf");
  fs::copy_file(kSource / "robots/ers210a/robot.yaml", dir / "robot.yaml");
  WriteFile(dir / "exp.yaml", "robot: " + (dir / "robot.yaml").string() + "\n");
}

// The shipped leg's URDF mutated in its structure and numbers (plant_urdf_* regressions), then
// read as a robot and built into the simulated plant, which runs a few ticks.
TEST_F(FuzzTest, UrdfToPlant) {
  WriteRobotFiles(dir_);
  Runner runner{"plant_urdf",
                {WithoutXmlComments(ReadFile(kSource / "robots/ers210a/leg.urdf"))},
                {},
                dir_ / "leg.urdf",
                [&] { LoadBuildAndTick(dir_ / "exp.yaml"); },
                StructureMutations()};
  Fuzz(runner);
}

// The shipped robot.yaml (in the air, and on the stand) mutated in its structure and numbers
// (plant_robot_* regressions), loaded through an experiment that names it by path, then built
// into the plant it describes, which runs a few ticks.
TEST_F(FuzzTest, RobotYamlToPlant) {
  WriteRobotFiles(dir_);
  const std::string air = WithoutYamlComments(ReadFile(kSource / "robots/ers210a/robot.yaml"));
  std::string stand = WithoutYamlComments(ReadFile(kSource / "robots/ers210a_stand/robot.yaml"));
  stand = stand.substr(stand.find("stand:"));
  Runner runner{"plant_robot",
                {air, air + stand},
                {},
                dir_ / "robot.yaml",
                [&] { LoadBuildAndTick(dir_ / "exp.yaml"); },
                StructureMutations()};
  Fuzz(runner);
}

}  // namespace
}  // namespace leglab::experiments
