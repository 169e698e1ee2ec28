#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "leglab/core/column_doc.h"

namespace CLI {
class App;
}

namespace leglab {

/// One file a program writes, declared beside the code that fills it: what `--list-outputs`
/// prints and docs/outputs.md holds. `file` may hold `<...>` for a part named at run time
/// ("trace_<mode>.csv"). A CSV's `columns` are its columns; a JSON file's are its fields, each
/// named by its dotted path (`<...>` for a key named at run time, `[]` for every element of a
/// list: "logs[].mae_deg.<rung>"). A file without them (Markdown, YAML) is described in prose.
struct OutputDoc {
  std::string_view file;
  std::string_view description;
  std::span<const ColumnDoc> columns;
};

/// The names of `columns`, in order: a CSV's header, a Python dict's keys.
std::vector<std::string> ColumnNames(std::span<const ColumnDoc> columns);

/// `outputs` as Markdown: per file a `### file` heading, its description, and its columns as a
/// table column | unit | description.
std::string OutputsMarkdown(std::span<const OutputDoc> outputs);

/// Adds `--list-outputs` to `app`: prints OutputsMarkdown(`outputs`) on stdout and exits with
/// status 0 before any other flag is checked.
void AddListOutputsFlag(CLI::App& app, std::span<const OutputDoc> outputs);

}  // namespace leglab
