#include "leglab/experiments/config.h"

namespace leglab::experiments {
namespace {

// A cell of a Markdown table: a | inside would end it.
std::string Cell(const std::string& text) {
  std::string out;
  for (const char c : text) {
    if (c == '|') out += '\\';
    out += c;
  }
  return out;
}

}  // namespace

std::string KeyTableMarkdown(const std::vector<KeyRow>& rows) {
  std::string table =
      "| key | type | default | range | unit | description |\n|---|---|---|---|---|---|\n";
  for (const KeyRow& row : rows) {
    table += "| `" + row.key + "` | " + Cell(row.type) + " | " + Cell(row.default_text) + " | " +
             Cell(row.range) + " | " + Cell(row.unit) + " | " + Cell(row.description) + " |\n";
  }
  return table;
}

}  // namespace leglab::experiments
