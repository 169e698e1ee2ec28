// A seeded random mutator over the three readers of user files: the config loader (YAML,
// extends:, --set), the desired-motion CSV reader and the URDF loader. Each execution mutates
// a seed input (the shipped files and a few hostile ones) and feeds it to the reader; the
// contract is that the reader either accepts it with every number it returns finite, or
// throws one of the bad-input exceptions the programs turn into exit status 2 (InputError,
// std::invalid_argument, std::domain_error). Anything else (another exception, a crash, a
// sanitizer report in the asan build) is a finding: the input is saved under
// $TMPDIR/leglab_fuzz_findings/ and should become a file in tests/experiments/fuzz_regressions/,
// which every run replays first.
//
// LEGLAB_FUZZ_EXECUTIONS sets the executions per reader (default 3000, so that the suite stays
// quick; .ci/run asks for 100000 in the release build); LEGLAB_FUZZ_SEED the seed (default 1:
// the same inputs every run). Each test prints its executions and findings.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

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
};

// Runs the replayed regressions, then LEGLAB_FUZZ_EXECUTIONS mutated inputs; returns findings.
void Fuzz(Runner& runner) {
  const fs::path findings_dir = fs::temp_directory_path() / "leglab_fuzz_findings";
  const long executions = EnvLong("LEGLAB_FUZZ_EXECUTIONS", 3000);
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
  long accepted = 0, refused = 0, found = 0;
  for (long i = 0; i < executions + static_cast<long>(replayed); ++i) {
    const std::string input =
        i < static_cast<long>(replayed)
            ? inputs[i]
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
      if (found >= 5) break;
    }
  }
  std::printf(
      "fuzz %s: %ld executions (+%zu regressions replayed), %ld accepted, %ld refused, "
      "%ld findings\n",
      runner.reader, executions, replayed, accepted, refused, found);
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

}  // namespace
}  // namespace leglab::experiments
