// `gilab slurm CONFIG`: an experiment as three dependent Slurm jobs (docs/cluster.md).
//   1. references: a job array, task i renders reference i, i + M, ... (`gilab run
//      --references-only --shard i/M`); each reference once, under the cache's lock;
//   2. runs: a job array of `gilab run --shard i/N`, after (1) has ended;
//   3. report: `gilab report`, after (2) has ended, whatever its tasks' exit codes.
// Slurm schedules; gilab only writes the sbatch scripts and calls sbatch.
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "core/util/atomic_file.h"
#include "core/util/error.h"
#include "experiments/cli/cli.h"
#include "experiments/runner/experiment_config.h"
#include "experiments/runner/runner.h"
#include "reference/cache.h"

namespace gilab::cli {
namespace {

namespace fs = std::filesystem;

/** 'text' for a POSIX shell (a ' inside becomes '\''). */
std::string shellQuote(const std::string& text) {
    std::string out = "'";
    for (char c : text)
        out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

struct JobSpec {
    std::string name;     // --job-name
    int arrayTasks = 0;   // 0: not an array
    bool gpu = false;     // gets --gres and the device selection
    std::string command;  // the shell line that does the work
};

struct Paths {
    fs::path gilab, config, outRoot, experiment, cache, logs, scripts, workDir;
};

/**
 * GILAB_DEVICE for a run task, unless the user set it: the first GPU Slurm gave the task
 * (CUDA_VISIBLE_DEVICES, an index in PCI order), else the task's local id on its node; without
 * --gres, lavapipe ("llvmpipe"), so a CPU node never picks up a GPU it was not given.
 */
std::string deviceSelection(bool gres) {
    if (!gres) return "export GILAB_DEVICE=\"${GILAB_DEVICE:-llvmpipe}\"  # no --gres: lavapipe\n";
    return "if [ -z \"${GILAB_DEVICE:-}\" ]; then\n"
           "    if [ -n \"${CUDA_VISIBLE_DEVICES:-}\" ]; then\n"
           "        export GILAB_DEVICE=\"${CUDA_VISIBLE_DEVICES%%,*}\"\n"
           "    else\n"
           "        export GILAB_DEVICE=\"${SLURM_LOCALID:-0}\"\n"
           "    fi\n"
           "fi\n";
}

std::string sbatchScript(const SlurmOptions& o, const Paths& p, const JobSpec& job) {
    std::string s = "#!/bin/bash\n";
    s += "# Written by: " + o.commandLine + "\n";
    s += "#SBATCH --job-name=" + job.name + "\n";
    s += "#SBATCH --chdir=" + p.workDir.string() + "\n";
    const std::string suffix = job.arrayTasks > 0 ? "%A_%a" : "%j";
    s += "#SBATCH --output=" + (p.logs / (job.name + "-" + suffix + ".out")).string() + "\n";
    if (job.arrayTasks > 0) s += "#SBATCH --array=0-" + std::to_string(job.arrayTasks - 1) + "\n";
    s += "#SBATCH --cpus-per-task=" + std::to_string(o.cpusPerTask) + "\n";
    if (!o.partition.empty()) s += "#SBATCH --partition=" + o.partition + "\n";
    if (!o.time.empty()) s += "#SBATCH --time=" + o.time + "\n";
    if (job.gpu && !o.gres.empty()) s += "#SBATCH --gres=" + o.gres + "\n";
    for (const std::string& a : o.sbatchArgs)
        s += "#SBATCH " + a + "\n";
    s += "set -euo pipefail\n";
    if (job.gpu) s += deviceSelection(!o.gres.empty());
    s += "echo \"gilab: job ${SLURM_JOB_ID:-?} task ${SLURM_ARRAY_TASK_ID:-none} on "
         "$(hostname -s)" +
         std::string(job.gpu ? ", GILAB_DEVICE=${GILAB_DEVICE:-default}" : "") + "\"\n";
    s += "exec " + job.command + "\n";
    return s;
}

/** Runs sbatch --parsable on `script`; returns the job id. */
std::string submit(const fs::path& script, const std::string& dependency) {
    std::string cmd = "sbatch --parsable";
    if (!dependency.empty()) cmd += " --dependency=" + dependency;
    cmd += " " + shellQuote(script.string()) + " 2>&1";
    FILE* pipe = ::popen(cmd.c_str(), "r");
    if (!pipe) throw Error("slurm: cannot run sbatch");
    std::string out;
    char buf[256];
    while (std::fgets(buf, sizeof buf, pipe))
        out += buf;
    const int status = ::pclose(pipe);
    while (!out.empty() && (out.back() == '\n' || out.back() == '\r'))
        out.pop_back();
    if (status != 0 || out.empty() || out.find_first_not_of("0123456789;") != std::string::npos) {
        if (status == 127 * 256 || out.find("not found") != std::string::npos)
            throw Error(
                "slurm: sbatch not found: run on a Slurm login node (Debian package "
                "slurm-client), or use --dry-run to see the scripts");
        throw Error("slurm: sbatch " + script.string() + " failed: " + out);
    }
    return out.substr(0, out.find(';'));  // "jobid[;cluster]"
}

}  // namespace

int runSlurm(const SlurmOptions& o) {
    const exp::ExperimentConfig config = exp::loadExperimentConfig(o.configPath);
    const std::vector<std::string> references = exp::listReferences(o.configPath);
    const size_t runCount = exp::expandRuns(config).size();

    Paths p;
    std::error_code ec;
    p.gilab = fs::read_symlink("/proc/self/exe", ec);
    if (ec) throw Error("slurm: cannot find the gilab binary (/proc/self/exe)");
    p.workDir = fs::current_path();
    p.config = fs::absolute(o.configPath).lexically_normal();
    p.outRoot = fs::absolute(o.outRoot).lexically_normal();
    p.experiment = p.outRoot / config.name;
    p.cache = fs::absolute(o.referenceCacheDir.empty() ? ref::ReferenceCache::defaultDir()
                                                       : fs::path(o.referenceCacheDir))
                  .lexically_normal();
    p.scripts = p.experiment / "slurm";
    p.logs = p.scripts / "logs";

    const int runShards = int(std::min<size_t>(size_t(o.shards), std::max<size_t>(runCount, 1)));
    const int refShards =
        o.referenceShards > 0
            ? o.referenceShards
            : int(std::min<size_t>(size_t(o.shards), std::max<size_t>(references.size(), 1)));
    const std::string common = " --out " + shellQuote(p.outRoot.string()) + " --reference-cache " +
                               shellQuote(p.cache.string()) + " --quiet";
    const std::string run = shellQuote(p.gilab.string()) + " run " + shellQuote(p.config.string());
    const std::string base = "gilab-" + config.name;
    const JobSpec jobs[3] = {
        {base + "-references", refShards, false,
         run + " --references-only --shard \"${SLURM_ARRAY_TASK_ID}/" + std::to_string(refShards) +
             "\"" + common},
        {base + "-runs", runShards, true,
         run + " --shard \"${SLURM_ARRAY_TASK_ID}/" + std::to_string(runShards) + "\"" + common},
        {base + "-report", 0, false,
         shellQuote(p.gilab.string()) + " report " + shellQuote(p.experiment.string())},
    };

    std::printf("%s: %zu runs in %d tasks; %zu distinct references in %d tasks; results in %s\n",
                config.name.c_str(), runCount, runShards, references.size(), refShards,
                p.experiment.string().c_str());
    if (o.dryRun) {
        for (const JobSpec& job : jobs)
            std::printf("\n# ---- %s.sbatch (dependency: %s)\n%s", job.name.c_str(),
                        &job == &jobs[0] ? "none" : "afterany on the previous job",
                        sbatchScript(o, p, job).c_str());
        return kExitOk;
    }

    fs::create_directories(p.logs);
    std::string ids[3];
    for (int i = 0; i < 3; ++i) {
        const fs::path script = p.scripts / (jobs[i].name + ".sbatch");
        writeFileAtomic(script, sbatchScript(o, p, jobs[i]));
        // afterany: the runs start even if a reference task failed (they render what is
        // missing themselves); the report shows whatever finished
        ids[i] = submit(script, i == 0 ? "" : "afterany:" + ids[i - 1]);
    }
    const std::string all = ids[0] + "," + ids[1] + "," + ids[2];
    std::printf("submitted: references job %s (%d tasks), runs job %s (%d tasks), report job %s\n",
                ids[0].c_str(), refShards, ids[1].c_str(), runShards, ids[2].c_str());
    std::printf("follow:    squeue -j %s\n", all.c_str());
    std::printf("history:   sacct -j %s --format=JobID,JobName,State,Elapsed,NodeList\n",
                all.c_str());
    std::printf("logs:      %s/\n", p.logs.string().c_str());
    std::printf("report:    %s/report.html (when job %s has run)\n", p.experiment.string().c_str(),
                ids[2].c_str());
    std::printf("resubmit:  the same command; finished runs and references are reused\n");
    return kExitOk;
}

}  // namespace gilab::cli
