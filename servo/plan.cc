// plan: requests for a real servo to follow a desired motion, from a model fitted to its logs
// (identify's log_fit.json), by either rung and either method. Writes requests.csv and
// plan.json into --out and prints a summary (docs/real-servos.md, "Requests for a real servo").
#include "leglab/servo/plan_program.h"

int main(int argc, char** argv) { return leglab::PlanMain(argc, argv); }
