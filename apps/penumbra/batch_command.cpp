// `penumbra batch`: job settings as `render` flags, the up-front checks, and the four modes.
#include "apps/penumbra/batch_command.h"

#include <algorithm>
#include <cstdio>
#include <functional>
#include <map>
#include <set>
#include <unordered_map>
#include <unordered_set>

#include "apps/penumbra/cli_support.h"
#include "apps/penumbra/exr_layers.h"
#include "apps/penumbra/progress.h"
#include "apps/penumbra/render_command.h"
#include "io/files/error.h"
#include "io/image/exr_merge.h"
#include "io/image/image_output.h"

namespace penumbra::cli {

namespace fs = std::filesystem;

namespace {

/// `render` flags a job sets through its own keys (or that make no sense in a job), with the
/// key to use instead.
const std::map<std::string, std::string>& reserved_settings() {
  static const std::map<std::string, std::string> m = {
      {"output", "the shot's \"output\""},
      {"png", "the shot's \"png\""},
      {"deep", "the shot's \"deep\""},
      {"no-png", "the shot's \"png\" (a shot without one writes no display image)"},
      {"camera", "the shot's \"camera\""},
      {"frame", "the shot's \"frames\""},
      {"frames", "the shot's \"frames\""},
      {"time", "the shot's \"frames\" (with the \"fps\" setting)"},
      {"tile", "the shot's \"tiles\""},
      {"crop", "the shot's \"tiles\""},
      {"stats-json", "the shot's \"stats_json\""},
      {"skip-existing", "`penumbra batch --skip-existing`"},
      {"overwrite", "`penumbra batch` (overwriting is the default)"},
      {"reproducible", "nothing: batch renders are always reproducible"},
      {"quiet", "`penumbra batch -q`"},
      {"progress", "`penumbra batch --progress`"},
      {"debug-pixel", "`penumbra render --debug-pixel`"},
      {"help", "`penumbra render --help`"},
      {"contact-sheet", "`penumbra render --contact-sheet` (a job's frames render as separate units)"},
      {"contact-sheet-columns", "`penumbra render --contact-sheet-columns`"},
  };
  return m;
}

/// What a unit or a whole shot renders.
struct Target {
  std::optional<int64_t> frame;  ///< one frame; none with `range` or for a still
  bool range = false;            ///< every frame of the shot
  int tile = 0, tiles = 1;
  bool quiet = false;
  int threads = 0;         ///< for a shot whose settings give none
  std::string max_memory;  ///< likewise
  std::string progress;    ///< `render --progress`; empty: its default
};

/// The command line of `render` for `target` of the shot, from its keys and settings; throws
/// InputError naming the setting for one `render` does not have or that the job sets itself.
std::vector<std::string> render_command_line(const Job& job, const JobShot& shot, const Target& t,
                                             const CLI::App& render) {
  std::vector<std::string> argv = {"penumbra-render", shot.scene.string()};
  const std::string out = t.frame ? substitute_frame(shot.output, *t.frame) : shot.output;
  argv.insert(argv.end(), {"-o", t.tiles > 1 ? tile_part_path(out, t.tile, t.tiles).string() : out});
  if (shot.png.empty() || t.tiles > 1)
    argv.push_back("--no-png");
  else
    argv.insert(argv.end(), {"--png", shot.png});
  if (!shot.deep.empty()) {
    const std::string deep = t.frame ? substitute_frame(shot.deep, *t.frame) : shot.deep;
    argv.insert(argv.end(), {"--deep", t.tiles > 1 ? tile_part_path(deep, t.tile, t.tiles).string() : deep});
  }
  if (!shot.stats_json.empty() && t.tiles == 1) argv.insert(argv.end(), {"--stats-json", shot.stats_json});
  if (!shot.camera.empty()) argv.insert(argv.end(), {"--camera", shot.camera});
  if (t.range && shot.frames) argv.insert(argv.end(), {"--frames", shot.frames_text});
  if (t.frame) argv.insert(argv.end(), {"--frame", std::to_string(*t.frame)});
  if (t.tiles > 1)
    argv.insert(argv.end(), {"--tile", std::to_string(t.tile) + "/" + std::to_string(t.tiles)});
  argv.push_back("--reproducible");
  if (t.quiet) argv.push_back("-q");
  if (!t.progress.empty() && t.progress != "auto") argv.push_back("--progress=" + t.progress);
  const auto sets = [&](const char* key) {
    for (const JobSetting& s : shot.settings)
      if (s.key == key) return true;
    return false;
  };
  if (t.threads > 0 && !sets("threads")) argv.insert(argv.end(), {"--threads", std::to_string(t.threads)});
  if (!t.max_memory.empty() && !sets("max-memory")) argv.insert(argv.end(), {"--max-memory", t.max_memory});
  for (const JobSetting& s : shot.settings) {
    const auto reserved = reserved_settings().find(s.key);
    if (reserved != reserved_settings().end())
      throw InputError(job.file.string(), s.where, "is set by " + reserved->second + ", not in settings");
    if (s.key == "turntable" && !shot.frames)
      throw InputError(job.file.string(), s.where,
                       "a turntable renders the shot's \"frames\" (e.g. \"0-35\" for 36 frames per turn)");
    // Batch renders are reproducible: nothing that depends on the clock.
    if (s.key == "time-limit")
      throw InputError(job.file.string(), s.where,
                       "a time limit makes a frame depend on the machine and differ between its stripes; "
                       "batch renders take every sample");
    if (s.key == "aov")
      for (const std::string& v : s.values)
        if (("," + v + ",").find(",cost,") != std::string::npos)
          throw InputError(
              job.file.string(), s.where,
              "the cost layer records times (cost_ns), which differ between runs; render it with "
              "`penumbra render --aov cost`");
    const CLI::Option* opt = render.get_option_no_throw("--" + s.key);
    if (!opt || s.key.size() < 2)
      throw InputError(job.file.string(), s.where,
                       "'" + s.key +
                           "' is not a setting (the long name of a `penumbra render` flag, such as "
                           "\"spp\" or \"integrator\")");
    const bool is_flag = opt->get_expected_max() == 0;  // CLI11's flags take no value
    if (is_flag != s.flag)
      throw InputError(
          job.file.string(), s.where,
          is_flag ? "is an on/off flag: give true or false" : "takes a value, not true or false");
    if (s.flag) {
      if (s.enabled) argv.push_back("--" + s.key);
      continue;
    }
    for (const std::string& v : s.values)
      argv.push_back("--" + s.key + "=" + v);  // a value may start with '-'
  }
  return argv;
}

/// `render`'s flags parsed from `argv` exactly as the command line would be.
RenderArgs parse_render_args(const Job& job, const JobShot& shot, const std::vector<std::string>& argv,
                             CLI::App& render, RenderArgs& args) {
  std::vector<const char*> c;
  for (const auto& s : argv) c.push_back(s.c_str());
  try {
    render.parse(int(c.size()), c.data());
  } catch (const CLI::ParseError& e) {
    throw InputError(job.file.string(), shot.where + ".settings", e.what());
  }
  note_given_options(render, int(c.size()), const_cast<char**>(c.data()), args);
  return args;
}

RenderArgs shot_target_args(const Job& job, const JobShot& shot, const Target& t) {
  RenderArgs args;
  CLI::App render;
  add_render_options(render, args);
  return parse_render_args(job, shot, render_command_line(job, shot, t, render), render, args);
}

/// f(), with bad input reported as an InputError that names the job file and the shot.
template <class F>
auto in_shot(const Job& job, const JobShot& shot, F f) -> decltype(f()) {
  try {
    return f();
  } catch (const InputError& e) {
    throw InputError(job.file.string(), shot.where, e.what());
  } catch (const UsageError& e) {
    throw InputError(job.file.string(), shot.where, e.what());
  } catch (const std::invalid_argument& e) {
    throw InputError(job.file.string(), shot.where, e.what());
  }
}

/// check_render() of the shot's flags, with the shot named in the message.
std::vector<std::pair<std::string, fs::path>> check_shot(const Job& job, const JobShot& shot,
                                                         const RenderArgs& args) {
  return in_shot(job, shot, [&] { return check_render(args); });
}

/// The tiled frames: per frame's first stripe unit, the units of its stripes.
std::vector<size_t> first_stripes(const PreparedJob& pj) {
  std::vector<size_t> out;
  for (size_t n = 0; n < pj.units.size(); ++n)
    if (const WorkUnit u = pj.units[n]; u.tiles > 1 && u.tile == 0) out.push_back(n);
  return out;
}

bool complete(const fs::path& exr) {
  std::string problem;
  return is_complete_exr(exr, problem);
}

/// The deep EXR of unit `u`'s frame (its stripe with `stripe`), or empty when the shot has none.
fs::path unit_deep(const JobShot& shot, const WorkUnit& u, bool stripe) {
  if (shot.deep.empty()) return {};
  const fs::path deep = substitute_frame(shot.deep, u.frame.value_or(0));
  return stripe ? tile_part_path(deep, u.tile, u.tiles) : deep;
}

/// Whether `exr` is complete, and with it the deep EXR `deep` when there is one (written first,
/// but a job given "deep" after its frames were rendered has none yet).
bool complete_with_deep(const fs::path& exr, const fs::path& deep) {
  return complete(exr) && (deep.empty() || complete(deep));
}

int list_units(const PreparedJob& pj) {
  for (size_t n = 0; n < pj.units.size(); ++n) {
    const WorkUnit u = pj.units[n];
    const std::string frame = u.frame ? std::to_string(*u.frame) : "-";
    const std::string tile = u.tiles > 1 ? std::to_string(u.tile) + "/" + std::to_string(u.tiles) : "-";
    std::printf("%zu\t%s\t%s\t%s\t%s\n", n, pj.job.shots[u.shot].name.c_str(), frame.c_str(), tile.c_str(),
                unit_output(pj.job, u).c_str());
  }
  return kExitOk;
}

int render_unit(const PreparedJob& pj, size_t n, const BatchArgs& b) {
  const WorkUnit u = pj.units[n];
  const fs::path final_exr = unit_output(pj.job, u);
  if (b.skip_existing && u.tiles > 1 &&
      complete_with_deep(final_exr, unit_deep(pj.job.shots[u.shot], u, false))) {
    if (prints_text(progress_mode(b.progress, b.quiet), b.quiet))
      std::fprintf(stderr, "penumbra: unit %zu: frame %s is complete; skipped\n", n,
                   final_exr.string().c_str());
    return kExitOk;
  }
  RenderArgs args = unit_render_args(pj, n);
  args.skip_existing = b.skip_existing;
  // An unfinished render of this unit (cancelled, preempted) continues from its resume state.
  std::error_code ec;
  args.resume = args.spec.integrator == "path" && fs::exists(fs::path(args.output).concat(".resume"), ec);
  return in_shot(pj.job, pj.job.shots[u.shot], [&] { return run_render(args); });
}

/// Merges tiled frame `first` (its first stripe's unit) and writes its display image; false
/// when a stripe is missing (reported).
bool merge_frame(const PreparedJob& pj, size_t first, const BatchArgs& b) {
  const WorkUnit u = pj.units[first];
  const JobShot& shot = pj.job.shots[u.shot];
  const fs::path final_exr = unit_output(pj.job, u);
  const fs::path png =
      shot.png.empty() ? fs::path() : fs::path(substitute_frame(shot.png, u.frame.value_or(0)));
  const RenderRequest q = check_render_args(pj.shot_args[u.shot]);
  // The merged frame's files as a whole-frame render of it would write them: none may be an
  // input (the scene, --env, the OCIO config) or the same file as another of them.
  check_shot(pj.job, shot,
             shot_target_args(
                 pj.job, shot,
                 {u.frame, false, 0, 1, true, pj.threads, pj.max_memory, pj.shot_args[u.shot].progress}));
  std::error_code ec;
  const fs::path final_deep = unit_deep(shot, u, false);
  if (b.skip_existing && complete_with_deep(final_exr, final_deep)) {
    if (!png.empty() && !fs::exists(png, ec))  // the merge ended before its display image
      write_display_image(read_exr_beauty(final_exr, q.budget), png, q.display);
    return true;
  }
  std::vector<fs::path> parts, deep_parts;
  std::string missing;
  bool any = false;
  for (int t = 0; t < u.tiles; ++t) {
    parts.push_back(tile_part_path(final_exr, t, u.tiles));
    any = any || fs::exists(parts.back(), ec);
    bool ok = complete(parts.back());
    if (!final_deep.empty()) {
      deep_parts.push_back(tile_part_path(final_deep, t, u.tiles));
      ok = ok && complete(deep_parts.back());
    }
    if (!ok) missing += (missing.empty() ? "" : ", ") + std::to_string(first + size_t(t));
  }
  if (!any && complete_with_deep(final_exr, final_deep)) return true;  // merged before, its stripes removed
  if (!missing.empty()) {
    std::fprintf(stderr,
                 "penumbra: error: %s: cannot merge %s: the stripes of units %s are missing or incomplete\n",
                 pj.job.file.string().c_str(), final_exr.string().c_str(), missing.c_str());
    return false;
  }
  MergeOptions options;
  options.max_memory_bytes = q.budget;
  try {
    // The deep frame first: the flat frame's presence marks the frame merged.
    if (!final_deep.empty()) merge_exr_parts(deep_parts, final_deep, options);
    merge_exr_parts(parts, final_exr, options);
  } catch (const InputError& e) {  // e.g. stripes of an earlier version of the job
    std::fprintf(stderr,
                 "penumbra: error: %s: cannot merge %s: %s (remove its .tile-*-of-%d.exr stripes and run "
                 "units %zu to %zu again)\n",
                 pj.job.file.string().c_str(), final_exr.string().c_str(), e.what(), u.tiles, first,
                 first + size_t(u.tiles) - 1);
    return false;
  }
  if (!png.empty()) write_display_image(read_exr_beauty(final_exr, q.budget), png, q.display);
  for (const fs::path& p : parts) fs::remove(p);
  for (const fs::path& p : deep_parts) fs::remove(p);
  if (prints_text(progress_mode(b.progress, b.quiet), b.quiet))
    std::fprintf(stderr, "penumbra: merged %d stripes into %s\n", u.tiles, final_exr.string().c_str());
  return true;
}

int merge_frames(const PreparedJob& pj, const BatchArgs& b) {
  int failed = 0;
  for (const size_t first : first_stripes(pj)) failed += merge_frame(pj, first, b) ? 0 : 1;
  return failed ? kExitInternal : kExitOk;
}

int render_all(const PreparedJob& pj, const BatchArgs& b) {
  for (size_t s = 0; s < pj.job.shots.size(); ++s) {
    if (prints_text(progress_mode(b.progress, b.quiet), b.quiet))
      std::fprintf(stderr, "penumbra: shot %s\n", pj.job.shots[s].name.c_str());
    RenderArgs args = pj.shot_args[s];
    args.skip_existing = b.skip_existing;
    if (const int rc = in_shot(pj.job, pj.job.shots[s], [&] { return run_render(args); }); rc != kExitOk)
      return rc;
  }
  return kExitOk;
}

/// Creates the folders every unit of `pj` writes into (a farm's output tree need not exist) and
/// returns those it made, parents first.
std::vector<fs::path> create_output_folders(const PreparedJob& pj) {
  std::set<fs::path> folders;
  for (size_t n = 0; n < pj.units.size(); ++n) {
    const WorkUnit u = pj.units[n];
    const JobShot& shot = pj.job.shots[u.shot];
    for (const std::string* pattern : {&shot.output, &shot.png, &shot.deep, &shot.stats_json})
      if (!pattern->empty())
        folders.insert(fs::path(u.frame ? substitute_frame(*pattern, *u.frame) : *pattern).parent_path());
  }
  std::vector<fs::path> made;
  for (const fs::path& f : folders) {
    std::vector<fs::path> missing;  // f and its parents that do not exist yet, innermost first
    std::error_code ec;
    for (fs::path p = f; !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
      missing.push_back(p);
      if (p == p.parent_path()) break;
    }
    fs::create_directories(f, ec);
    if (ec)
      throw InputError(pj.job.file.string(), "",
                       "cannot create the output folder " + f.string() + ": " + ec.message());
    made.insert(made.end(), missing.rbegin(), missing.rend());
  }
  return made;
}

/// The files unit `n` writes: a frame's EXR (or a stripe) and its resume state and Cryptomatte
/// sidecars; a whole frame's display image and statistics, or for the first stripe the merged
/// frame, its display image and sidecars (the merge's). `crypto` are the shots' Cryptomatte
/// layers. (The cost image is not among them: the cost layer is refused in jobs.)
template <typename F>
void unit_files(const PreparedJob& pj, size_t n, const std::vector<std::vector<std::string>>& crypto, F&& f) {
  const WorkUnit u = pj.units[n];
  const JobShot& shot = pj.job.shots[u.shot];
  const auto at = [&](const std::string& pattern) {
    return u.frame ? substitute_frame(pattern, *u.frame) : pattern;
  };
  const std::string out = at(shot.output);
  const fs::path exr = u.tiles > 1 ? tile_part_path(out, u.tile, u.tiles) : fs::path(out);
  f(exr.string());
  f(exr.string() + ".resume");
  if (!shot.deep.empty()) {
    const std::string deep = at(shot.deep);
    f(u.tiles > 1 ? tile_part_path(deep, u.tile, u.tiles).string() : deep);
    if (u.tile == 0 && u.tiles > 1) f(deep);
  }
  for (const std::string& layer : crypto[u.shot]) f(crypto_sidecar_path(exr, layer).string());
  if (u.tile > 0) return;
  if (u.tiles > 1) f(out);
  if (!shot.png.empty()) f(at(shot.png));
  if (!shot.stats_json.empty() && u.tiles == 1) f(at(shot.stats_json));
  if (u.tiles > 1)
    for (const std::string& layer : crypto[u.shot]) f(crypto_sidecar_path(out, layer).string());
}

/// Throws InputError unless `real` (absolute, lexically normal, links resolved) lies in
/// `real_root` (likewise, without a trailing separator); `file` is how the job names it.
void check_in_root(const PreparedJob& pj, size_t n, const fs::path& root, const std::string& real_root,
                   const std::string& file, const std::string& real) {
  const std::string& r = real_root;
  const bool inside =
      r == "/" || (real.size() > r.size() + 1 && real.compare(0, r.size(), r) == 0 && real[r.size()] == '/');
  if (!inside)
    throw InputError(pj.job.file.string(), pj.job.shots[pj.units[n].shot].where,
                     file + (real == file ? "" : " (" + real + ")") + " is outside the output root " +
                         root.string() +
                         " (a job writes inside its own folder unless `--output-root DIR` allows another; "
                         "the job's \"output_root\" can only narrow it)");
}

/// `p` lexically normal without a trailing separator.
fs::path folder_path(fs::path p) {
  p = p.lexically_normal();
  return p.has_filename() || p == p.root_path() ? p : p.parent_path();
}

/// `p` with its symbolic links resolved as far as it exists (folder_path form); throws
/// InputError naming the job file when they cannot be (a folder that cannot be read).
fs::path resolved(const PreparedJob& pj, const fs::path& p) {
  std::error_code ec;
  const fs::path real = fs::weakly_canonical(p, ec);
  if (ec) throw InputError(pj.job.file.string(), "", "cannot resolve " + p.string() + ": " + ec.message());
  return folder_path(real);
}

/// `file`, a symbolic link, followed to what a write through it replaces (its target, through
/// chains of links, dangling ones included), its folders resolved.
fs::path resolved_link(const PreparedJob& pj, const fs::path& file) {
  fs::path target = file;
  for (int hops = 0; hops < 40; ++hops) {
    std::error_code ec;
    if (!fs::is_symlink(target, ec)) return resolved(pj, target);
    const fs::path next = fs::read_symlink(target, ec);
    if (ec)
      throw InputError(pj.job.file.string(), "",
                       "cannot read the link " + target.string() + ": " + ec.message());
    target = next.is_absolute() ? next : target.parent_path() / next;
  }
  throw InputError(pj.job.file.string(), "", file.string() + ": too many levels of symbolic links");
}

/// Where files would really be written: each folder's links resolved once, and a file that is
/// itself a symbolic link (writes follow it) resolved to its target.
class RealPaths {
 public:
  explicit RealPaths(const PreparedJob& pj) : m_pj(pj) {}
  std::string operator()(const std::string& file) {
    const fs::path p(file);
    const std::string dir = p.parent_path().native();
    auto it = m_folders.find(dir);
    if (it == m_folders.end()) it = m_folders.emplace(dir, scan(p.parent_path())).first;
    const std::string name = p.filename().native();
    if (it->second.links.count(name)) return resolved_link(m_pj, p).native();
    return it->second.real == "/" ? "/" + name : it->second.real + "/" + name;
  }

 private:
  struct Folder {
    std::string real;                       ///< the folder, links resolved
    std::unordered_set<std::string> links;  ///< its entries that are symbolic links
  };
  Folder scan(const fs::path& dir) const {
    Folder f{resolved(m_pj, dir).native(), {}};
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
      if (std::error_code lec; it->is_symlink(lec)) f.links.insert(it->path().filename().native());
    return f;
  }
  const PreparedJob& m_pj;
  std::unordered_map<std::string, Folder> m_folders;
};

/// Every file every unit writes lies in the output root once links are resolved (in its
/// folders and in the file itself): the root is --output-root or the job file's folder, the
/// job's "output_root" may only narrow it. Checked before any folder is made.
void check_output_root(const PreparedJob& pj, const BatchArgs& b,
                       const std::vector<std::vector<std::string>>& crypto) {
  fs::path root =
      folder_path(b.output_root.empty() ? pj.job.file.parent_path() : fs::absolute(b.output_root));
  std::string real_root = resolved(pj, root).native();
  if (!pj.job.output_root.empty()) {
    const fs::path narrowed = folder_path(pj.job.output_root);
    const std::string real = resolved(pj, narrowed).native();
    const bool inside = real_root == "/" || real == real_root ||
                        (real.compare(0, real_root.size(), real_root) == 0 &&
                         real.size() > real_root.size() && real[real_root.size()] == '/');
    if (!inside)
      throw InputError(
          pj.job.file.string(), "output_root",
          narrowed.string() + (real == narrowed.native() ? "" : " (" + real + ")") + " is outside " +
              root.string() +
              (b.output_root.empty() ? ", the job file's folder (`--output-root DIR` allows more)"
                                     : ", the --output-root"));
    root = narrowed;
    real_root = real;
  }
  RealPaths real(pj);
  for (size_t n = 0; n < pj.units.size(); ++n)
    unit_files(pj, n, crypto,
               [&](const std::string& file) { check_in_root(pj, n, root, real_root, file, real(file)); });
}

/// No two units (nor two outputs of one unit) write the same file: a hash of each path,
/// sorted, and the writers of a repeated hash looked up again, so that memory grows by 8 bytes
/// per file.
void check_unit_files(const PreparedJob& pj, const std::vector<std::vector<std::string>>& crypto) {
  RealPaths real(pj);  // a link to another unit's file is that file
  std::vector<uint64_t> hashes;
  for (size_t n = 0; n < pj.units.size(); ++n)
    unit_files(pj, n, crypto,
               [&](const std::string& file) { hashes.push_back(std::hash<std::string>{}(real(file))); });
  std::sort(hashes.begin(), hashes.end());
  std::set<uint64_t> repeated;
  for (size_t i = 1; i < hashes.size(); ++i)
    if (hashes[i] == hashes[i - 1]) repeated.insert(hashes[i]);
  if (repeated.empty()) return;
  std::map<std::string, size_t> writer;  // only the files whose hash repeats
  for (size_t n = 0; n < pj.units.size(); ++n)
    unit_files(pj, n, crypto, [&](const std::string& file) {
      const std::string path = real(file);
      if (!repeated.count(std::hash<std::string>{}(path))) return;
      const auto [it, fresh] = writer.emplace(path, n);
      if (fresh) return;
      const WorkUnit u = pj.units[n], v = pj.units[it->second];
      const auto name = [&](const WorkUnit& w, size_t i) {
        return pj.job.shots[w.shot].where + " (unit " + std::to_string(i) +
               (w.frame ? ", frame " + std::to_string(*w.frame) : "") +
               (w.tiles > 1 ? ", stripe " + std::to_string(w.tile) + "/" + std::to_string(w.tiles) : "") +
               ")";
      };
      throw InputError(pj.job.file.string(), pj.job.shots[u.shot].where,
                       file + " would be written by " + name(v, it->second) + " and by " + name(u, n));
    });
}

/// Stripes must not outnumber the rows of a frame whose height the settings give.
void check_stripes(const PreparedJob& pj, size_t s) {
  const RenderArgs& args = pj.shot_args[s];
  const size_t first = pj.units.first_of_shot(s), count = pj.units.units_of_shot(s);
  for (size_t n = first; n < first + count; ++n) {
    const WorkUnit u = pj.units[n];
    if (u.tiles <= 1) continue;
    if (args.spec.height > 0 && u.tiles > args.spec.height)
      throw InputError(pj.job.file.string(), pj.job.shots[s].where + ".tiles",
                       std::to_string(u.tiles) + " stripes of a frame " + std::to_string(args.spec.height) +
                           " rows high: at most one stripe per row");
    return;  // every tiled frame of the shot has the same split
  }
}

/// Checks the first and last frame's flags and outputs as `render` would, one stripe of
/// each tiled shot, the stripes against the rows, and every file the units write (check_unit_files).
void check_shots(PreparedJob& pj, const BatchArgs& b) {
  std::vector<std::vector<std::string>> crypto(pj.job.shots.size());
  for (size_t s = 0; s < pj.job.shots.size(); ++s) {
    const JobShot& shot = pj.job.shots[s];
    check_stripes(pj, s);
    // The range's patterns ('#' in every output), then its first and last frame in full.
    in_shot(pj.job, shot, [&] { return check_frame_patterns(pj.shot_args[s]); });
    const size_t first = pj.units.first_of_shot(s), last = first + pj.units.units_of_shot(s) - 1;
    for (const size_t n : {first, last}) {
      const WorkUnit u = pj.units[n];
      const RenderArgs args = shot_target_args(
          pj.job, shot, {u.frame, false, 0, 1, b.quiet, b.threads, b.max_memory, b.progress});
      check_shot(pj.job, shot, args);
      crypto[s] = in_shot(pj.job, shot, [&] { return check_render_args(args).crypto; });
    }
    for (size_t n = first; n <= last; ++n)  // one stripe of each tiled shot: its split of the rows
      if (const WorkUnit u = pj.units[n]; u.tiles > 1) {
        check_shot(
            pj.job, shot,
            shot_target_args(pj.job, shot,
                             {u.frame, false, 0, u.tiles, b.quiet, b.threads, b.max_memory, b.progress}));
        break;
      }
  }
  check_unit_files(pj, crypto);
}

}  // namespace

PreparedJob prepare_job(const BatchArgs& b, bool create_folders) {
  PreparedJob pj;
  pj.job = read_job_file(b.job_file);
  pj.units = JobUnits(pj.job, b.tiles);
  pj.threads = b.threads;
  pj.max_memory = b.max_memory;
  for (const JobShot& shot : pj.job.shots)  // every shot's settings as `render`'s flags
    pj.shot_args.push_back(shot_target_args(
        pj.job, shot, {std::nullopt, true, 0, 1, b.quiet, b.threads, b.max_memory, b.progress}));
  // Nothing is made outside the output root (Cryptomatte sidecars lie beside their EXR).
  check_output_root(pj, b, std::vector<std::vector<std::string>>(pj.job.shots.size()));
  if (create_folders) pj.made_folders = create_output_folders(pj);
  try {
    check_shots(pj, b);
  } catch (...) {
    remove_made_folders(pj);  // a refused job leaves nothing behind
    throw;
  }
  return pj;
}

void remove_made_folders(PreparedJob& pj) {
  for (auto it = pj.made_folders.rbegin(); it != pj.made_folders.rend(); ++it) {
    std::error_code ec;
    fs::remove(*it, ec);  // only while empty
  }
  pj.made_folders.clear();
}

RenderArgs unit_render_args(const PreparedJob& pj, size_t n) {
  const WorkUnit u = pj.units.at(n);
  const JobShot& shot = pj.job.shots[u.shot];
  return shot_target_args(pj.job, shot,
                          {u.frame, false, u.tile, u.tiles, pj.shot_args[u.shot].quiet, pj.threads,
                           pj.max_memory, pj.shot_args[u.shot].progress});
}

bool unit_complete(const PreparedJob& pj, size_t n) {
  const WorkUnit u = pj.units.at(n);
  const fs::path final_exr = unit_output(pj.job, u);
  const JobShot& shot = pj.job.shots[u.shot];
  return complete_with_deep(final_exr, unit_deep(shot, u, false)) ||
         (u.tiles > 1 &&
          complete_with_deep(tile_part_path(final_exr, u.tile, u.tiles), unit_deep(shot, u, true)));
}

int run_batch(const BatchArgs& b) {
  PreparedJob pj = prepare_job(b, true);
  if (b.list) {
    remove_made_folders(pj);  // listing writes nothing
    return list_units(pj);
  }
  if (b.unit) {
    if (*b.unit < 0 || uint64_t(*b.unit) >= pj.units.size())
      throw UsageError("--unit " + std::to_string(*b.unit) + ": " + b.job_file + " has units 0 to " +
                       std::to_string(pj.units.size() - 1) + " (`penumbra batch --list` prints them)");
    return render_unit(pj, size_t(*b.unit), b);
  }
  if (b.merge) return merge_frames(pj, b);
  return render_all(pj, b);
}

}  // namespace penumbra::cli
