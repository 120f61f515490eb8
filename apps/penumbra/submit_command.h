// `penumbra submit slurm JOB.json`: a job file's work units submitted to Slurm as one array job
// (each task runs `penumbra batch JOB.json --unit $SLURM_ARRAY_TASK_ID --skip-existing`, retried
// a bounded number of times and requeued by Slurm when a node fails) and, when frames are tiled,
// a merge job that runs after the array succeeds (`--dependency=afterok`). Only the units whose
// outputs are not complete yet are submitted, so submitting again finishes an interrupted job.
// CPUs and memory per task come from the shots' threads and memory budget.
#pragma once

#include <string>

namespace penumbra::cli {

struct SubmitArgs {
  std::string job_file;
  int tiles = 1;            ///< stripes per frame for shots without "tiles"
  std::string partition;    ///< empty: the cluster's default
  bool dry_run = false;     ///< print the scripts and the sbatch commands; write no script, submit nothing
  int threads = 0;          ///< CPUs per task for shots whose settings give no threads
  std::string max_memory;   ///< memory budget for shots whose settings give none
  int retries = 2;          ///< attempts after a failed one, per task (bad input is not retried)
  std::string scripts;      ///< folder for the scripts and logs; default JOB.slurm beside the job
  std::string time_limit;   ///< Slurm --time per task (e.g. 2:00:00); empty: the partition's
  std::string output_root;  ///< `batch --output-root` for every task; empty: the job file's folder
};

/// Runs `submit slurm`. Returns the exit code: 0 submitted (or nothing left to do), 2 bad
/// input (the job file, a shot without threads or memory), 1 sbatch missing or failing.
int run_submit_slurm(const SubmitArgs& args);

}  // namespace penumbra::cli
