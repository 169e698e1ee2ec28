#pragma once

#include "leglab/app/yaml_config.h"
#include "leglab/servo/log_fit.h"

namespace leglab {

/// Reads the Structured `logs.*` keys (train, validate, v_max_deg_s) from the `logs` section
/// `reader` is in. Throws InputError naming the key on a value of the wrong shape.
void ReadLogFitStructured(YamlKeyReader& reader, LogFitConfig& c);

}  // namespace leglab
