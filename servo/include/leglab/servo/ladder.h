#pragma once

#include <functional>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "leglab/servo/servo_model.h"

namespace leglab {

/// Who predicts with a rung of the servo model ladder.
enum class RungKind {
  kBaseline,  ///< no parameters: the request itself, the best time shift in hindsight
  kModel,     ///< a model identify fits to each motor's training logs
  kLearned,   ///< a network leglab.servo.learned trains (not fitted by identify)
};

/// One rung of the servo model ladder, as servo/ladder.json declares it.
struct ServoRung {
  std::string name;  ///< log_fit.json's key (mae_deg.<name>), the log CSV's <name>_deg
  RungKind kind = RungKind::kModel;
  std::string label;        ///< its heading in tables
  std::string description;  ///< what it predicts, a phrase: log_fit.md's key to its columns
  std::string column;       ///< the log CSV column's description
};

/// The ladder as servo/ladder.json declares it (compiled in), in the order tables show it.
/// Throws std::logic_error (a bug) when the file compiled in is malformed.
std::span<const ServoRung> ServoLadder();

/// A model's parameters by name (log_fit.json's models.<rung>.<motor>, its tick aside).
using RungParameters = std::map<std::string, double>;

/// A model rung identify fits and scores beside the ladder's own (the paper's model and the
/// extended model are built in): fitted per motor on its training logs, and per fold when
/// cross-validated, then scored on every log, written to log_fit.json, log_fit.md and each
/// log's CSV. Both functions may be called from several threads at once.
struct ModelRung {
  ServoRung rung;  ///< kind kModel; a name no other rung has
  /// Fits the parameters to one motor's training recordings, resampled on `tick_s` (s); may
  /// throw std::invalid_argument when they cannot be fitted (a bad input, naming the rung).
  std::function<RungParameters(std::span<const ServoRecording> train, double tick_s)> fit;
  /// The angle predicted at every tick of `recording` (deg, its size), open loop from its
  /// requests and, where a driven run begins, its measured angle.
  std::function<std::vector<double>(const RungParameters& parameters,
                                    const ServoRecording& recording, double tick_s)>
      predict;
};

/// The model rungs identify implements beyond the built-in paper and extended models: one for
/// each further rung of kind kModel in servo/ladder.json (ImplementedModelRungs in
/// servo/src/ladder.cc). Throws std::logic_error (a bug) when a ladder rung of kind kBaseline
/// or kModel has no implementation.
std::span<const ModelRung> LadderModelRungs();

}  // namespace leglab
