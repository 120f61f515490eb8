// Command-line parse errors as `penumbra` reports them: CLI11's ParseError turned into
// `penumbra: error:` lines, with the closest known option or command suggested for a typo
// (Damerau-Levenshtein distance over the names of the subcommand the command line selects).
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace penumbra::cli {

/// The optimal-string-alignment (restricted Damerau-Levenshtein) distance: the fewest
/// insertions, deletions, substitutions and swaps of two adjacent characters that turn `a`
/// into `b` ("sp" -> "spp": 1, "rendr" -> "render": 1, "tiel" -> "tile": 1).
int edit_distance(std::string_view a, std::string_view b);

/// The candidate closest to `word` by edit_distance, if it is close enough: at most 2 edits or
/// a third of the word's length, whichever is more, and fewer edits than the word has
/// characters (so no one-letter word is "corrected" into an unrelated one). Ties go to the
/// earlier candidate. Empty when none is close enough.
std::string closest_name(std::string_view word, const std::vector<std::string>& candidates);

/// The messages (without the "penumbra: error: " prefix) for a failed parse of `app` over
/// argv: "unknown option --sp (did you mean --spp?)" for each unknown option of the selected
/// subcommand, "unknown command rendr (did you mean render?)", "a command is required: ...",
/// else CLI11's own message. Not for CLI::Success (--help, --version).
std::vector<std::string> parse_error_messages(CLI::App& app, const CLI::ParseError& error, int argc,
                                              char** argv);

}  // namespace penumbra::cli
