#include "leglab/app/program.h"

#include <CLI/CLI.hpp>
#include <array>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <new>
#include <stdexcept>
#include <string_view>
#include <system_error>

#include "leglab/app/input_error.h"
#include "leglab/app/output.h"

namespace leglab {

void RefuseEmptyValues(CLI::App& app) {
  const CLI::Validator non_empty(
      [](const std::string& value) {
        return value.empty() ? std::string("an empty value (give one, or leave the option out)")
                             : std::string();
      },
      "NOT EMPTY");
  for (CLI::Option* option : app.get_options()) {
    if (option->get_type_size_max() > 0) option->check(non_empty);
  }
  for (CLI::App* subcommand : app.get_subcommands([](CLI::App*) { return true; })) {
    RefuseEmptyValues(*subcommand);
  }
}

void AddListKeysFlag(CLI::App& app, const std::function<std::string()>& table) {
  app.add_flag_callback(
      "--list-keys",
      [table] {
        std::cout << table();
        throw CLI::Success();
      },
      "print the config keys this program reads (a Markdown table: key, type, default, range, "
      "unit, description) and exit");
}

std::string MessageLine(std::string_view text, size_t max_bytes) {
  std::string out;
  size_t i = 0;
  for (; i < text.size() && out.size() < max_bytes; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c == '\n') {
      out += "\\n";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c < 0x20 || c == 0x7F) {
      std::array<char, 8> hex{};
      std::snprintf(hex.data(), hex.size(), "\\x%02x", static_cast<unsigned>(c));
      out += hex.data();
    } else if (text.substr(i, 3) == "\xEF\xBB\xBF") {  // U+FEFF, a byte-order mark
      out += "\\ufeff";
      i += 2;
    } else if (text.substr(i, 2) == "\xE2\x80" && i + 2 < text.size() &&
               (static_cast<unsigned char>(text[i + 2]) & 0xF0) == 0x80 &&
               static_cast<unsigned char>(text[i + 2]) <= 0x8F) {  // U+2000..U+200F: spaces
      std::array<char, 12> code{};
      std::snprintf(code.data(), code.size(), "\\u20%02x",
                    static_cast<unsigned>(text[i + 2] & 0x0F));
      out += code.data();
      i += 2;
    } else {
      out += static_cast<char>(c);
    }
  }
  if (i >= text.size()) return out;
  // Cut on a character's first byte, never inside a UTF-8 sequence.
  while (i < text.size() && (static_cast<unsigned char>(text[i]) & 0xC0) == 0x80) {
    out += text[i++];
  }
  return out + " ... (" + std::to_string(text.size() - i) + " more bytes)";
}

std::string MarkdownText(std::string_view text) {
  std::string marked;
  marked.reserve(text.size());
  for (const char c : text) {
    if (c == '|') {
      marked += "\\|";
    } else if (c == '<') {
      marked += "&lt;";
    } else {
      marked += c;
    }
  }
  // Control and invisible characters as MessageLine shows them, with nothing cut.
  return MessageLine(marked, std::string::npos);
}

int ReportErrors(const std::string& program, const std::function<void()>& body) {
  const auto report = [&program](const char* kind, const char* what) {
    std::cerr << program << ": " << kind << ": " << MessageLine(what) << '\n';
  };
  try {
    body();
    // The tables on stdout are part of the result: a full disk or a closed pipe is a failure.
    std::cout.flush();
    if (!std::cout) {
      std::cerr << program << ": failed: cannot write to standard output\n";
      return 1;
    }
    return 0;
  } catch (const InputError& e) {
    report("error", e.what());
  } catch (const std::invalid_argument& e) {
    report("error", e.what());
  } catch (const std::domain_error& e) {
    report("error", e.what());
  } catch (const OutputError& e) {
    report("failed", e.what());
    return 1;
  } catch (const std::filesystem::filesystem_error& e) {
    report("failed", e.what());
    return 1;
  } catch (const std::bad_alloc&) {
    std::cerr << program << ": internal error: out of memory (std::bad_alloc)\n";
    return 1;
  } catch (const std::exception& e) {
    report("internal error", e.what());
    return 1;
  } catch (...) {
    std::cerr << program << ": internal error: an unknown exception\n";
    return 1;
  }
  return 2;
}

}  // namespace leglab
