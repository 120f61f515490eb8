// `penumbra deep flatten | merge | holdout`.
#include "apps/penumbra/deep_command.h"

#include <cctype>
#include <cstdio>
#include <filesystem>

#include "apps/penumbra/cli_support.h"
#include "io/files/atomic_file.h"
#include "io/files/error.h"
#include "io/files/file_checks.h"
#include "io/image/deep_exr.h"

namespace penumbra::cli {

namespace fs = std::filesystem;

namespace {

/// The inputs read within the budget, each checked for what merge and holdout need.
std::vector<DeepImage> read_inputs(const std::vector<std::string>& files, uint64_t budget, bool combine) {
  std::vector<DeepImage> images;
  uint64_t used = 0;
  for (const std::string& file : files) {
    images.push_back(read_deep_exr(file, budget - used));
    const DeepImage& img = images.back();
    used += deep_image_bytes(img.counts.size(), img.samples.size());
    if (!combine) continue;
    if (!same_window(img, images.front()))
      throw InputError(file, "",
                       "covers another window than " + files.front() + " (" + std::to_string(img.width) +
                           "x" + std::to_string(img.height) + " at " + std::to_string(img.origin_x) + "," +
                           std::to_string(img.origin_y) + " of " + std::to_string(img.full_width) + "x" +
                           std::to_string(img.full_height) +
                           "); merge and holdout take renders of one frame");
    for (const DeepSample& s : img.samples)
      if (s.zback != s.z)
        throw InputError(file, "ZBack",
                         "holds volumetric samples (ZBack > Z), which merge and holdout do not split; "
                         "oiiotool --deepmerge does");
  }
  // The result: a merge holds every input's samples again, a flat image four floats a pixel.
  if (used > budget / 2)
    throw InputError(files.front(), "",
                     "the inputs' samples and the result would need " + format_bytes(2 * used) +
                         ", over the " + format_bytes(budget) + " limit (--max-memory)");
  return images;
}

void check_output(const DeepArgs& a) {
  std::string ext = fs::path(a.output).extension().string();
  for (auto& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".exr") throw UsageError("-o " + a.output + ": the output must be an .exr file");
  resolve_output(a.output, "-o");
  std::vector<std::pair<std::string, fs::path>> inputs;
  for (size_t k = 0; k < a.inputs.size(); ++k)
    inputs.push_back({"input " + std::to_string(k + 1), a.inputs[k]});
  if (!a.by.empty()) inputs.push_back({"--by", a.by});
  check_distinct_files({{"-o", a.output}}, inputs);
}

ExrOptions flat_options(const std::string& operation) {
  ExrOptions o;
  o.half = false;
  o.metadata = {{"penumbra:deep_operation", operation}};
  return o;
}

}  // namespace

DeepCommands add_deep_command(CLI::App& app, DeepArgs& a) {
  DeepCommands c;
  c.deep = app.add_subcommand("deep", "Composite deep EXRs (render --deep): flatten, merge, hold out");
  c.deep->require_subcommand(1);
  c.flatten = c.deep->add_subcommand("flatten", "The flat RGBA image a deep EXR's samples composite to");
  c.flatten->add_option("input", a.inputs, "a deep EXR")->required()->expected(1);
  c.merge =
      c.deep->add_subcommand("merge", "Deep EXRs of one frame rendered apart, merged into one deep EXR");
  c.merge->add_option("inputs", a.inputs, "two or more deep EXRs of the same frame and window")
      ->required()
      ->expected(2, -1);
  c.holdout = c.deep->add_subcommand(
      "holdout", "A deep EXR held out by another: its part of their merge, as a flat RGBA image");
  c.holdout->add_option("input", a.inputs, "the deep EXR to keep")->required()->expected(1);
  c.holdout->add_option("--by", a.by, "the deep EXR that holds it out (same frame and window)")->required();
  for (CLI::App* sub : {c.flatten, c.merge, c.holdout}) {
    sub->add_option("-o,--output", a.output, "the result EXR (written atomically)")->required();
    sub->add_option("--max-memory", a.max_memory,
                    "budget for the inputs' samples and the result, e.g. 4G (default: half the RAM)");
  }
  return c;
}

int run_deep(const DeepCommands& c, const DeepArgs& a) {
  check_output(a);
  const uint64_t budget = memory_budget(a.max_memory);
  if (c.flatten->parsed()) {
    const std::vector<DeepImage> in = read_inputs(a.inputs, budget, false);
    write_exr(flatten_deep(in[0]), a.output, flat_options("flatten"));
  } else if (c.merge->parsed()) {
    const std::vector<DeepImage> in = read_inputs(a.inputs, budget, true);
    std::vector<const DeepImage*> images;
    for (const DeepImage& img : in) images.push_back(&img);
    ExrOptions o;
    o.metadata = {{"penumbra:deep_operation", "merge"}};
    write_deep_exr(merge_deep(images), a.output, o);
  } else {
    const std::vector<DeepImage> in = read_inputs({a.inputs[0], a.by}, budget, true);
    write_exr(holdout_deep(in[0], in[1]), a.output, flat_options("holdout"));
  }
  std::printf("%s\n", a.output.c_str());
  return kExitOk;
}

}  // namespace penumbra::cli
