#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace CLI {
class App;
}

namespace leglab {

/// Adds `--list-keys` to `app`: prints `table()` (KeyTableMarkdown of the keys the program
/// reads) on stdout and exits with status 0 before any other flag is checked.
void AddListKeysFlag(CLI::App& app, const std::function<std::string()>& table);

/// Makes every option of `app` and of its subcommands that takes a value refuse an empty one
/// (`--mass-kg ''`), which CLI11 would otherwise read as 0 or the default: a parse error that
/// names the option. Call it once all options are added, before parsing.
void RefuseEmptyValues(CLI::App& app);

/// What every experiment program takes: `--config FILE`, `--out DIR`, `--threads N`,
/// `--progress` or `--quiet`, `--list-keys`, and any number of `--set key=value` applied
/// last.
struct ProgramArgs {
  std::string config_path;
  std::string out_dir;
  std::vector<std::string> overrides;
  int threads = 0;        ///< 0: one per core
  bool progress = false;  ///< --progress: plain progress lines on stderr, even when not a terminal
  bool quiet = false;     ///< --quiet: no progress at all
};

/// `text` as one line of a message: line breaks and other control characters escaped (\n,
/// \r, \xNN), invisible characters shown (a byte-order mark as \ufeff, U+2000..U+200F as
/// \u20NN), and cut after about `max_bytes` bytes (never inside a UTF-8 sequence) with how
/// many more there were: a message that echoes a whole file or list stays one short line.
std::string MessageLine(std::string_view text, size_t max_bytes = 300);

/// User text (a file, motor or trajectory name) as one Markdown table cell or heading that
/// shows it as written: a `|` would end the cell, `<` start HTML markup on the results page,
/// and a control character (a newline) break the line, so they are escaped as `\|`, `&lt;`
/// and as MessageLine escapes them (`\n`, `\xNN`, `\ufeff`).
std::string MarkdownText(std::string_view text);

/// Runs `body` and reports what escapes it as RunProgram does (bad input: "<program>: error:
/// <message>", status 2; a failure to write: "<program>: failed: ...", 1; anything else:
/// "<program>: internal error: ...", 1). Returns 0 when `body` returns.
int ReportErrors(const std::string& program, const std::function<void()>& body);

}  // namespace leglab
