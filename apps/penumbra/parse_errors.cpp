// Parse errors with suggestions: the selected subcommand is found by walking argv through the
// subcommand names, its option names are the candidates for an unknown option.
#include "apps/penumbra/parse_errors.h"

#include <algorithm>

namespace penumbra::cli {

namespace {

/// The subcommand of `app` named `name`, or null.
CLI::App* find_command(CLI::App& app, const std::string& name) {
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; }))
    if (sub->get_name() == name) return sub;
  return nullptr;
}

std::vector<std::string> command_names(CLI::App& app) {
  std::vector<std::string> names;
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) names.push_back(sub->get_name());
  return names;
}

/// "penumbra", "penumbra render", "penumbra submit slurm": the command as typed.
std::string command_path(const std::vector<CLI::App*>& chain) {
  std::string path = "penumbra";
  for (size_t i = 1; i < chain.size(); ++i) path += " " + chain[i]->get_name();
  return path;
}

/// Every spelling of the options of `app`: "--spp", "-o", "--output", ...
std::vector<std::string> option_names(CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::Option* opt : app.get_options()) {
    for (const std::string& n : opt->get_lnames()) names.push_back("--" + n);
    for (const std::string& n : opt->get_snames()) names.push_back("-" + n);
  }
  return names;
}

std::string strip_dashes(std::string_view s) {
  while (!s.empty() && s.front() == '-') s.remove_prefix(1);
  return std::string(s);
}

/// "unknown option --sp (did you mean --spp?)" for `arg` ("--sp", "--sp=4", "-spp").
std::string unknown_option(CLI::App& app, const std::string& path, const std::string& arg) {
  const std::string name = arg.substr(0, arg.find('='));
  const std::vector<std::string> names = option_names(app);
  // Compared without their dashes, so that "-spp" finds "--spp" and "--o" finds "-o".
  std::vector<std::string> bare;
  for (const std::string& n : names) bare.push_back(strip_dashes(n));
  const std::string best = closest_name(strip_dashes(name), bare);
  if (best.empty()) return "unknown option " + name + " (" + path + " --help lists the options)";
  const auto at = size_t(std::find(bare.begin(), bare.end(), best) - bare.begin());
  return "unknown option " + name + " (did you mean " + names[at] + "?)";
}

}  // namespace

int edit_distance(std::string_view a, std::string_view b) {
  // d[i][j]: distance between the first i characters of a and the first j of b (Wagner-Fischer
  // with adjacent transpositions, Damerau 1964), three rows kept.
  std::vector<int> before(b.size() + 1), last(b.size() + 1), row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) last[j] = int(j);
  for (size_t i = 1; i <= a.size(); ++i) {
    row[0] = int(i);
    for (size_t j = 1; j <= b.size(); ++j) {
      const int cost = a[i - 1] == b[j - 1] ? 0 : 1;
      row[j] = std::min({last[j] + 1, row[j - 1] + 1, last[j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        row[j] = std::min(row[j], before[j - 2] + 1);
    }
    std::swap(before, last);
    std::swap(last, row);
  }
  return last[b.size()];
}

std::string closest_name(std::string_view word, const std::vector<std::string>& candidates) {
  const int limit = std::max<int>(2, int(word.size()) / 3);
  int best_distance = limit + 1;
  std::string best;
  for (const std::string& c : candidates) {
    const int d = edit_distance(word, c);
    if (d < best_distance && d < int(word.size())) {
      best_distance = d;
      best = c;
    }
  }
  return best;
}

std::vector<std::string> parse_error_messages(CLI::App& app, const CLI::ParseError& error, int argc,
                                              char** argv) {
  // The subcommands argv selects, and the first word that names none where one is expected.
  std::vector<CLI::App*> chain = {&app};
  std::string unknown_command;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    CLI::App& at = *chain.back();
    if (command_names(at).empty()) break;  // the subcommand's own options and values follow
    if (arg.empty() || arg[0] == '-') continue;
    if (CLI::App* sub = find_command(at, arg)) {
      chain.push_back(sub);
      continue;
    }
    unknown_command = arg;
    break;
  }
  CLI::App& selected = *chain.back();
  const std::string path = command_path(chain);
  const std::string under = chain.size() > 1 ? " for " + path.substr(9) : "";
  if (!unknown_command.empty()) {
    const std::string best = closest_name(unknown_command, command_names(selected));
    return {"unknown command " + unknown_command + under +
            (best.empty() ? " (" + path + " --help lists the commands)" : " (did you mean " + best + "?)")};
  }
  // CLI11 names some errors after the app that throws them: told apart by type.
  if (dynamic_cast<const CLI::RequiredError*>(&error) && !command_names(selected).empty() &&
      std::string(error.what()).find("ubcommand") != std::string::npos) {
    std::string names;
    for (const std::string& n : command_names(selected)) names += (names.empty() ? "" : ", ") + n;
    return {"a command is required" + under + ": " + names + " (" + path + " --help describes them)"};
  }
  if (dynamic_cast<const CLI::ExtrasError*>(&error)) {
    std::vector<std::string> messages, others;
    std::vector<std::string> extras;  // those of every command on the way, in command-line order
    for (const CLI::App* command : chain)
      for (const std::string& arg : command->remaining()) extras.push_back(arg);
    const auto position = [&](const std::string& arg) { return std::find(argv, argv + argc, arg) - argv; };
    std::stable_sort(extras.begin(), extras.end(),
                     [&](const std::string& a, const std::string& b) { return position(a) < position(b); });
    for (const std::string& arg : extras) {
      if (arg.size() > 1 && arg[0] == '-')
        messages.push_back(unknown_option(selected, path, arg));
      else
        others.push_back(arg);
    }
    // Words after an unknown option are most likely its value: only reported on their own.
    if (messages.empty() && !others.empty()) {
      std::string list;
      for (const std::string& o : others) list += (list.empty() ? "" : " ") + o;
      messages.push_back("unexpected argument" + std::string(others.size() > 1 ? "s " : " ") + list + " (" +
                         path + " --help lists what it takes)");
    }
    if (!messages.empty()) return messages;
  }
  return {error.what()};
}

}  // namespace penumbra::cli
