#include "leglab/app/output_docs.h"

#include <CLI/CLI.hpp>
#include <iostream>

namespace leglab {

std::vector<std::string> ColumnNames(std::span<const ColumnDoc> columns) {
  std::vector<std::string> names;
  names.reserve(columns.size());
  for (const ColumnDoc& c : columns) names.emplace_back(c.name);
  return names;
}

std::string OutputsMarkdown(std::span<const OutputDoc> outputs) {
  std::string md;
  for (const OutputDoc& output : outputs) {
    md += "### `";
    md += output.file;
    md += "`\n\n";
    md += output.description;
    md += "\n";
    if (!output.columns.empty()) {
      // A JSON file's are its fields, named by their dotted paths.
      const bool json = output.file.ends_with(".json");
      md += json ? "\n| field | unit | description |\n|---|---|---|\n"
                 : "\n| column | unit | description |\n|---|---|---|\n";
      for (const ColumnDoc& c : output.columns) {
        md += "| `";
        md += c.name;
        md += "` | ";
        md += c.unit;
        md += " | ";
        md += c.description;
        md += " |\n";
      }
    }
    md += "\n";
  }
  return md;
}

void AddListOutputsFlag(CLI::App& app, std::span<const OutputDoc> outputs) {
  app.add_flag_callback(
      "--list-outputs",
      [outputs] {
        std::cout << OutputsMarkdown(outputs);
        throw CLI::Success();
      },
      "print the files this program writes and their columns (Markdown) and exit");
}

}  // namespace leglab
