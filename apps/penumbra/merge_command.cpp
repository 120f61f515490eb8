// `penumbra merge`.
#include "apps/penumbra/merge_command.h"

#include <cctype>
#include <cstdio>
#include <filesystem>

#include "apps/penumbra/cli_support.h"
#include "apps/penumbra/progress.h"
#include "io/files/atomic_file.h"
#include "io/image/exr_denoise.h"
#include "io/image/exr_merge.h"

namespace penumbra::cli {

namespace fs = std::filesystem;

int run_merge(const MergeArgs& a) {
  const fs::path merged(a.output);
  std::string ext = merged.extension().string();
  for (auto& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".exr") throw UsageError("-o " + a.output + ": the output must be an .exr file");
  std::vector<fs::path> parts(a.parts.begin(), a.parts.end());
  std::vector<std::pair<std::string, fs::path>> inputs;
  for (size_t k = 0; k < parts.size(); ++k) inputs.push_back({"part " + std::to_string(k + 1), parts[k]});
  check_distinct_files({{"-o", merged}}, inputs);
  MergeOptions options;
  options.force = a.force;
  options.max_memory_bytes = memory_budget(a.max_memory);
  merge_exr_parts(parts, merged, options);
  std::printf("%s\n", a.output.c_str());
  return kExitOk;
}

int run_denoise(const DenoiseArgs& a) {
  const fs::path out(a.output);
  std::string ext = out.extension().string();
  for (auto& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".exr") throw UsageError("-o " + a.output + ": the output must be an .exr file");
  check_distinct_files({{"-o", out}}, {{"input", fs::path(a.input)}});
  ExrDenoiseOptions options;
  options.noisy_main = a.denoise_main == "noisy";
  options.config.threads = a.threads;
  options.max_memory_bytes = memory_budget(a.max_memory);
  const ProgressMode mode = progress_mode(a.progress, a.quiet);
  ProgressReporter progress(mode, "denoise");
  options.progress = [&](int done, int total) { progress(done, total); };
  set_phase("denoising");
  (void)denoise_exr(a.input, out, options);
  progress.finish();
  std::printf("%s\n", a.output.c_str());
  return kExitOk;
}

}  // namespace penumbra::cli
