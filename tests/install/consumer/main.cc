// A program of another project, built against an installed leglab: the model's C_m for a line
// of slope 1 deg/tick with the paper's Table 1 parameters, and the simulated leg's rotator
// after 25 ticks of a 10 deg request. Usage: consumer <leg.urdf>
#include <cstdio>

#include "leglab/model/line_inverse.h"
#include "leglab/model/paper.h"
#include "leglab/sim/leg_sim.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: consumer <leg.urdf>\n");
    return 2;
  }
  const leglab::JointModelParams paper = leglab::paper::kTable1;  // 2.5, 7, 4, 6
  std::printf("C_m = %.4f deg\n", leglab::LineInverseOffsetExact(paper, 1.0));

  leglab::sim::SimConfig config;
  config.urdf_path = argv[1];
  leglab::sim::LegSim leg(config);
  leg.SetRequestsDeg({10.0, 0.0, 0.0});
  for (int tick = 0; tick < 25; ++tick) leg.Tick();
  std::printf("rotator = %.1f deg\n", leg.TrueDeg()[leglab::kRotator]);
  return 0;
}
