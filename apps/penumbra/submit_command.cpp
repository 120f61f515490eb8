// `penumbra submit slurm`: resources, the sbatch scripts and their submission.
#include "apps/penumbra/submit_command.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <vector>

#include "apps/penumbra/batch_command.h"
#include "apps/penumbra/cli_support.h"
#include "io/farm/job_file.h"
#include "io/files/atomic_file.h"
#include "io/files/error.h"
#include "io/image/exr_merge.h"

namespace penumbra::cli {

namespace fs = std::filesystem;

namespace {

/// Memory a task asks for beyond the render's budget: the program, its libraries and thread stacks.
constexpr uint64_t kTaskOverheadMiB = 512;

/// Throws UsageError when `text`, which goes into a generated script (`what` names it), holds a
/// control character: a newline would end a comment or a directive line and start a command
/// or an `#SBATCH` line of its own. Every other byte (quotes, `$`, backquotes, non-UTF-8) is
/// safe in a comment and inside single quotes. Returns `text`.
const std::string& script_text(const std::string& text, const char* what) {
  if (const auto bad = control_character(text))
    throw UsageError(std::string(what) + " '" + printable(text) + "' contains the control character 0x" +
                     *bad + ": it cannot go into a generated script");
  return text;
}

/// `s` in single quotes for sh (after script_text()).
std::string quoted(const std::string& s) {
  script_text(s, "a script argument");
  std::string q = "'";
  for (const char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

/// What every task asks Slurm for: the most CPUs and memory any shot renders with.
struct Resources {
  int cpus = 1;
  uint64_t mem_mib = 0;
};

Resources task_resources(const PreparedJob& pj) {
  Resources r;
  for (size_t s = 0; s < pj.job.shots.size(); ++s) {
    const RenderArgs& args = pj.shot_args[s];
    const std::string& where = pj.job.shots[s].where;
    if (args.spec.threads <= 0)
      throw InputError(
          pj.job.file.string(), where,
          "gives no \"threads\" setting: the CPUs each task asks Slurm for (set it in the job, or "
          "--threads)");
    if (args.max_memory.empty())
      throw InputError(
          pj.job.file.string(), where,
          "gives no \"max-memory\" setting: the memory each task asks Slurm for (set it in the job, "
          "or --max-memory)");
    r.cpus = std::max(r.cpus, args.spec.threads);
    r.mem_mib = std::max(r.mem_mib, (parse_bytes(args.max_memory) + (uint64_t(1) << 20) - 1) >> 20);
  }
  r.mem_mib += kTaskOverheadMiB;
  return r;
}

/// "0-2,5,7-8" for the sorted indices.
std::string array_spec(const std::vector<size_t>& units) {
  std::string spec;
  for (size_t i = 0; i < units.size();) {
    size_t j = i;
    while (j + 1 < units.size() && units[j + 1] == units[j] + 1) ++j;
    spec +=
        (spec.empty() ? "" : ",") + std::to_string(units[i]) + (j > i ? "-" + std::to_string(units[j]) : "");
    i = j + 1;
  }
  return spec;
}

/// The `batch` options every task passes on, so that its units are the ones listed here.
std::string batch_options(const SubmitArgs& a) {
  std::string o;
  if (a.tiles > 1) o += " --tiles " + std::to_string(a.tiles);
  if (a.threads > 0) o += " --threads " + std::to_string(a.threads);
  if (!a.max_memory.empty()) o += " --max-memory " + quoted(a.max_memory);
  if (!a.output_root.empty())
    o += " --output-root " + quoted(fs::absolute(a.output_root).lexically_normal().string());
  return o;
}

/// The job's name on the cluster: the job file's stem (letters, digits, '.', '_', '-' kept) and
/// a hash of its absolute path, so that two job files never share a name.
std::string job_name(const fs::path& job_file, const char* kind) {
  std::string stem;
  for (const char c : job_file.stem().string())
    stem += std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-' ? c : '_';
  uint32_t h = 2166136261u;  // FNV-1a
  for (const char c : job_file.string()) h = (h ^ uint8_t(c)) * 16777619u;
  char hex[9];
  std::snprintf(hex, sizeof hex, "%08x", h);
  return std::string("penumbra-") + kind + "-" + stem.substr(0, 64) + "-" + hex;
}

/// The sbatch options that hold text from outside (names, paths), quoted for the shell; `%` in
/// the log path is Slurm's pattern character, doubled to stand for itself.
std::string named_options(const std::string& name, const fs::path& log_dir, const std::string& log_pattern) {
  std::string dir;
  for (const char c : log_dir.string()) dir += c == '%' ? std::string("%%") : std::string(1, c);
  return "--job-name=" + quoted(name) + " --output=" + quoted(dir + "/" + log_pattern);
}

/// Throws UsageError unless `value` is a plain Slurm word (a partition or a time limit).
void check_slurm_word(const std::string& value, const char* option) {
  if (value.empty()) return;
  for (const char c : value)
    if (!std::isalnum(static_cast<unsigned char>(c)) && !std::strchr("_.,:-", c))
      throw UsageError(std::string(option) + " '" + value +
                       "': only letters, digits and _ . , : - (a Slurm partition name or time)");
}

std::string sbatch_header(const Resources& r, int cpus, const SubmitArgs& a) {
  std::string h = "#!/bin/sh\n";
  h += "#SBATCH --cpus-per-task=" + std::to_string(cpus) + "\n";
  h += "#SBATCH --mem=" + std::to_string(r.mem_mib) + "M\n";
  h += "#SBATCH --requeue\n";
  if (!a.partition.empty()) h += "#SBATCH --partition=" + a.partition + "\n";
  if (!a.time_limit.empty()) h += "#SBATCH --time=" + a.time_limit + "\n";
  return h;
}

std::string render_script(const PreparedJob& pj, const SubmitArgs& a, const Resources& r,
                          const std::vector<size_t>& pending, const std::string& exe) {
  std::string s = sbatch_header(r, r.cpus, a);
  s += "#SBATCH --array=" + array_spec(pending) + "\n";
  s += "# One work unit of " + script_text(pj.job.file.string(), "the job file") +
       " per array task (`penumbra batch --list` prints them).\n";
  s += "# A failed unit is run again up to " + std::to_string(a.retries) +
       " times; bad input (exit 2) and a cancel or interrupt (130, 143: Slurm requeues what it preempts) are "
       "not.\n";
  s += "# A cancel signals every process of the task: the shell outlives it (the trap) and waits for\n"
       "# penumbra to stop gracefully (the frame marked unfinished, its resume state written, no\n"
       "# temporaries), since the task ends, and its processes are killed, when the shell exits.\n";
  s += "retries=" + std::to_string(a.retries) + "\nattempt=0\nstopped=0\n";
  s += "trap 'stopped=1' TERM INT HUP\n";
  s += "while :; do\n";
  s += "  " + quoted(exe) + " batch " + quoted(pj.job.file.string()) +
       " --unit \"$SLURM_ARRAY_TASK_ID\" --skip-existing" + batch_options(a) + " &\n";
  s += "  pid=$!\n";
  s += "  while :; do wait \"$pid\"; rc=$?; kill -0 \"$pid\" 2>/dev/null || break; done\n";
  s += "  case \"$rc\" in 0 | 2 | 130 | 143) exit \"$rc\" ;; esac\n";
  s += "  if [ \"$stopped\" = 1 ]; then exit \"$rc\"; fi\n";
  s += "  if [ \"$attempt\" -ge \"$retries\" ]; then exit \"$rc\"; fi\n";
  s += "  attempt=$((attempt + 1))\n";
  s += "  echo \"penumbra: unit $SLURM_ARRAY_TASK_ID exited with $rc; attempt $((attempt + 1)) of "
       "$((retries + 1))\" >&2\n";
  s += "done\n";
  return s;
}

std::string merge_script(const PreparedJob& pj, const SubmitArgs& a, const Resources& r,
                         const std::string& exe) {
  std::string s = sbatch_header(r, 1, a);
  s += "#SBATCH --kill-on-invalid-dep=yes\n";  // a failed array leaves no merge job waiting forever
  s += "# Assembles every tiled frame of " + script_text(pj.job.file.string(), "the job file") +
       " from its stripes.\n";
  s += "exec " + quoted(exe) + " batch " + quoted(pj.job.file.string()) + " --merge --skip-existing" +
       batch_options(a) + "\n";
  return s;
}

/// True when `sbatch` is an executable file in a folder of $PATH.
bool sbatch_on_path() {
  const char* path = std::getenv("PATH");
  if (!path) return false;
  std::string dirs = path;
  for (size_t i = 0; i <= dirs.size();) {
    const size_t j = std::min(dirs.find(':', i), dirs.size());
    const fs::path candidate =
        fs::path(dirs.substr(i, j - i).empty() ? "." : dirs.substr(i, j - i)) / "sbatch";
    if (access(candidate.c_str(), X_OK) == 0) return true;
    i = j + 1;
  }
  return false;
}

/// The standard output of the shell command `command` and its wait status in `status`; throws
/// std::runtime_error when it cannot be started.
std::string command_output(const std::string& command, int& status) {
  FILE* p = popen(command.c_str(), "r");
  if (!p) throw std::runtime_error("cannot run " + command + ": " + std::string(std::strerror(errno)));
  std::string out;
  char buf[512];
  while (size_t n = std::fread(buf, 1, sizeof buf, p)) out.append(buf, n);
  status = pclose(p);
  return out;
}

/// Runs `sbatch --parsable ARGS SCRIPT` (its messages go to stderr) and returns the job id;
/// throws std::runtime_error when it fails or prints no job id.
std::string sbatch(const std::string& args, const fs::path& script) {
  int status = 0;
  std::string out = command_output("sbatch --parsable " + args + " " + quoted(script.string()), status);
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  const std::string id = out.substr(0, out.find(';'));  // "ID" or "ID;CLUSTER"
  const bool numeric = !id.empty() && id.find_first_not_of("0123456789") == std::string::npos;
  if (status != 0 || !numeric)
    throw std::runtime_error("sbatch " + script.string() + " failed" +
                             (WIFEXITED(status) && WEXITSTATUS(status) != 0
                                  ? " with exit " + std::to_string(WEXITSTATUS(status))
                                  : "") +
                             (numeric ? "" : " (it printed no job id: '" + out.substr(0, 200) + "')") +
                             "; its messages are above");
  return id;
}

/// The ids of the jobs of `name` still queued or running (empty when squeue cannot tell).
std::string queued_jobs(const std::string& name) {
  int status = 0;
  std::string out = command_output("squeue -h -o %i -n " + quoted(name) + " 2>/dev/null", status);
  if (status != 0) return "";
  for (char& c : out)
    if (c == '\n') c = ' ';
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

void write_script(const fs::path& path, const std::string& text) {
  write_atomically(path,
                   [&](const fs::path& temp) { write_file_checked(temp, text.data(), text.size(), path); });
  fs::permissions(path, fs::perms::owner_exec | fs::perms::group_exec, fs::perm_options::add);
}

}  // namespace

int run_submit_slurm(const SubmitArgs& a) {
  check_slurm_word(a.partition, "--partition");
  check_slurm_word(a.time_limit, "--time");
  BatchArgs b;
  b.job_file = a.job_file;
  b.tiles = a.tiles;
  b.threads = a.threads;
  b.max_memory = a.max_memory;
  b.output_root = a.output_root;
  b.quiet = true;
  PreparedJob pj = prepare_job(b, true);  // the checks need the output folders
  Resources r;
  try {
    r = task_resources(pj);
  } catch (...) {
    remove_made_folders(pj);
    throw;
  }
  std::vector<size_t> pending;
  bool merge_needed = false;
  for (size_t n = 0; n < pj.units.size(); ++n) {
    if (!unit_complete(pj, n)) pending.push_back(n);
    if (const WorkUnit u = pj.units[n]; u.tiles > 1 && u.tile == 0 && !merge_needed) {
      std::string problem;
      merge_needed = !is_complete_exr(unit_output(pj.job, u), problem);
    }
  }
  if (pending.empty() && !merge_needed) {
    remove_made_folders(pj);
    std::fprintf(stderr, "penumbra: every frame of %s is complete; nothing to submit\n", a.job_file.c_str());
    return kExitOk;
  }
  const fs::path dir =
      a.scripts.empty() ? fs::path(pj.job.file).replace_extension(".slurm") : fs::absolute(a.scripts);
  script_text(dir.string(), "--scripts");
  const std::string exe = script_text(fs::read_symlink("/proc/self/exe").string(), "the penumbra executable");
  const std::string render = pending.empty() ? "" : render_script(pj, a, r, pending, exe);
  const std::string merge = merge_needed ? merge_script(pj, a, r, exe) : "";
  const std::string render_name = job_name(pj.job.file, "render"),
                    merge_name = job_name(pj.job.file, "merge");
  const std::string render_options = named_options(render_name, dir, "render-%A_%a.log");
  const std::string merge_options = named_options(merge_name, dir, "merge-%j.log");
  if (a.dry_run) {
    remove_made_folders(pj);  // a dry run writes nothing
    if (!render.empty())
      std::printf("# %s\n%s\n# sbatch --parsable %s %s\n\n", (dir / "render.sbatch").c_str(), render.c_str(),
                  render_options.c_str(), quoted((dir / "render.sbatch").string()).c_str());
    if (!merge.empty())
      std::printf("# %s\n%s\n# sbatch --parsable %s%s %s\n", (dir / "merge.sbatch").c_str(), merge.c_str(),
                  merge_options.c_str(), render.empty() ? "" : " --dependency=afterok:<the array job>",
                  quoted((dir / "merge.sbatch").string()).c_str());
    return kExitOk;
  }
  if (!sbatch_on_path())
    throw std::runtime_error(
        "sbatch is not on PATH: is Slurm installed on this machine? (--dry-run prints the "
        "scripts without submitting)");
  // Units still running would be submitted twice, and two merges of one frame race.
  for (const std::string& name : {render_name, merge_name})
    if (const std::string ids = queued_jobs(name); !ids.empty())
      throw UsageError("jobs of " + pj.job.file.string() + " are still queued or running (" + ids +
                       "); submit again when they have ended, or scancel them");
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw std::runtime_error("cannot create " + dir.string() + ": " + ec.message());
  std::string array_id;
  if (!render.empty()) {
    write_script(dir / "render.sbatch", render);
    array_id = sbatch(render_options, dir / "render.sbatch");
    std::printf("array %s\n", array_id.c_str());
    std::fprintf(stderr,
                 "penumbra: submitted array job %s: %zu of %zu units (%s), %d CPUs and %llu MiB each\n",
                 array_id.c_str(), pending.size(), pj.units.size(), array_spec(pending).c_str(), r.cpus,
                 static_cast<unsigned long long>(r.mem_mib));
  }
  if (!merge.empty()) {
    write_script(dir / "merge.sbatch", merge);
    std::string merge_id;
    try {
      merge_id = sbatch(merge_options + (array_id.empty() ? "" : " --dependency=afterok:" + array_id),
                        dir / "merge.sbatch");
    } catch (const std::runtime_error& e) {
      if (array_id.empty()) throw;
      throw std::runtime_error(std::string(e.what()) + "; array job " + array_id +
                               " is submitted: when it has ended, submit again for the merge");
    }
    std::printf("merge %s\n", merge_id.c_str());
    std::fprintf(stderr, "penumbra: submitted merge job %s%s\n", merge_id.c_str(),
                 array_id.empty() ? "" : (" (runs when array job " + array_id + " has succeeded)").c_str());
  }
  std::fprintf(stderr, "penumbra: scripts and logs in %s\n", dir.c_str());
  return kExitOk;
}

}  // namespace penumbra::cli
