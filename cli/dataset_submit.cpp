// zcheck dataset submit: `dataset verify` as a Slurm job array of shards, each resuming its own
// results file, and a report job after them all. Slurm is reached only through its commands
// (sbatch, squeue), started with posix_spawnp.
#include "dataset_options.h"

#include "zcheck/atomic_file.h"
#include "zcheck/error.h"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <climits>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <thread>

extern char** environ;

namespace zcheck::cli {

namespace {

namespace fs = std::filesystem;

// 'text' for a POSIX shell: single quotes, each ' written as '\''.
std::string shellQuoted(const std::string& text)
{
    std::string out = "'";
    for (char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

// Runs a program (found on PATH) and returns its standard output; its exit status in `status`.
std::string runProgram(const std::vector<std::string>& argv, int& status)
{
    int fds[2];
    if (::pipe(fds) != 0) throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, fds[1], STDOUT_FILENO);
    posix_spawn_file_actions_addclose(&actions, fds[0]);
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    pid_t pid = 0;
    const int spawned = posix_spawnp(&pid, args[0], &actions, nullptr, args.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    ::close(fds[1]);
    if (spawned != 0) {
        ::close(fds[0]);
        throw Error("cannot run '" + argv[0] + "': " + std::strerror(spawned) + " (is Slurm installed and on PATH?)");
    }
    std::string out;
    char buffer[4096];
    for (ssize_t n; (n = ::read(fds[0], buffer, sizeof buffer)) != 0;) {
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) break;
        out.append(buffer, std::size_t(n));
    }
    ::close(fds[0]);
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    return out;
}

// The job id `sbatch --parsable` prints ("123" or "123;cluster").
std::string submitted(const std::vector<std::string>& argv)
{
    int status = 0;
    std::string out = runProgram(argv, status);
    const std::string id = out.substr(0, out.find_first_of(";\n"));
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || id.empty() || id.find_first_not_of("0123456789_") != std::string::npos)
        throw Error("sbatch refused the job (" + argv.back() + "): " + (out.empty() ? "no output" : printableExcerpt(out, 200)));
    return id;
}

std::string executablePath()
{
    char path[PATH_MAX];
    const ssize_t n = ::readlink("/proc/self/exe", path, sizeof path - 1);
    if (n <= 0) throw std::runtime_error("cannot find the zcheck executable's path (/proc/self/exe)");
    return std::string(path, std::size_t(n));
}

struct SubmitOptions {
    DatasetVerifyOptions verify;
    std::string out;
    int tasks = 0;
    std::vector<std::string> sbatchArguments;
    bool wait = false, dryRun = false;
};

int runDatasetSubmit(const SubmitOptions& o)
{
    // The source and options are checked here, once, before anything is submitted: a bad option
    // fails now, not in every task.
    {
        DatasetRunOptions options = runOptions(o.verify);
        options.parseShard("0/" + std::to_string(o.tasks));
        const DatasetRunner check(openSource(o.verify), options, [](const std::string&, const DepthMapReading&, int, int) -> DepthMapFile {
            throw Error("not read");
        });
    }
    const std::vector<std::string> verifyArguments = verifyArgumentsOf(o.verify);
    const std::string exe = executablePath();
    const std::string dir = fs::absolute(o.out).lexically_normal().string();
    const std::string cwd = fs::current_path().string();
    OutputFiles outputs;
    outputs.addFolder(dir, "--out");
    outputs.add(dir + "/verify.sbatch", "--out");
    outputs.add(dir + "/report.sbatch", "--out");
    std::string header;
    for (const std::string& a : o.sbatchArguments) header += "#SBATCH " + a + "\n";
    std::string verify = "#!/bin/bash\n# zcheck dataset submit: shard $SLURM_ARRAY_TASK_ID of " + std::to_string(o.tasks) +
                         "\n#SBATCH --job-name=zcheck-verify\n#SBATCH --array=0-" + std::to_string(o.tasks - 1) +
                         "\n#SBATCH --chdir=" + cwd + "\n#SBATCH --output=" + dir + "/logs/verify-%a.out\n" + header +
                         "set -uo pipefail\nexec " + shellQuoted(exe) + " dataset verify";
    for (const std::string& a : verifyArguments) verify += " " + shellQuoted(a);
    verify += " --shard \"$SLURM_ARRAY_TASK_ID/" + std::to_string(o.tasks) + "\" -o " + shellQuoted(dir) +
              "/results-\"$SLURM_ARRAY_TASK_ID\".jsonl --resume\n";
    const std::string report = "#!/bin/bash\n# zcheck dataset submit: the report after every shard\n"
                               "#SBATCH --job-name=zcheck-report\n#SBATCH --chdir=" + cwd + "\n#SBATCH --output=" + dir +
                               "/logs/report.out\n" + header + "set -uo pipefail\nresults=()\nfor i in $(seq 0 " +
                               std::to_string(o.tasks - 1) + "); do\n  f=" + shellQuoted(dir) +
                               "/results-$i.jsonl\n  [[ -s $f ]] && results+=(\"$f\")\ndone\n" + shellQuoted(exe) +
                               " dataset report \"${results[@]}\" --out " + shellQuoted(dir) + "\nstatus=$?\necho $status > " +
                               shellQuoted(dir + "/report.status") + "\nexit $status\n";
    outputs.writeText(dir + "/verify.sbatch", verify);
    outputs.writeText(dir + "/report.sbatch", report);
    outputs.commit();
    fs::create_directories(dir + "/logs");
    std::error_code ignored;
    fs::remove(dir + "/report.status", ignored);
    if (o.dryRun) {
        std::cout << "wrote " << dir << "/verify.sbatch (" << o.tasks << " tasks) and " << dir << "/report.sbatch\n";
        return kExitConsistent;
    }
    const std::string verifyJob = submitted({"sbatch", "--parsable", dir + "/verify.sbatch"});
    const std::string reportJob = submitted({"sbatch", "--parsable", "--dependency=afterany:" + verifyJob, dir + "/report.sbatch"});
    std::cout << "verify job " << verifyJob << " (" << o.tasks << " tasks), report job " << reportJob << "\nresults in " << dir
              << "\n"
              << std::flush;
    if (!o.wait) return kExitConsistent;
    // The report job is done when squeue no longer lists it.
    while (true) {
        int status = 0;
        const std::string listed = runProgram({"squeue", "-h", "-j", reportJob, "-o", "%i"}, status);
        if (WIFEXITED(status) && WEXITSTATUS(status) == 0 && listed.find_first_not_of(" \n") == std::string::npos) break;
        std::this_thread::sleep_for(std::chrono::seconds(2));
    }
    std::ifstream statusFile(dir + "/report.status");
    int reportStatus = -1;
    if (!(statusFile >> reportStatus))
        throw Error("the report job " + reportJob + " ended without a status: see " + dir + "/logs/report.out");
    std::ifstream summary(dir + "/summary.json");
    std::cout << summary.rdbuf();
    return reportStatus == 0 ? kExitConsistent : reportStatus == 1 ? kExitInconsistent : kExitUsage;
}

}  // namespace

std::function<int()> addDatasetSubmitCommand(CLI::App* dataset)
{
    auto submit = std::make_shared<SubmitOptions>();
    CLI::App* submitCommand = dataset->add_subcommand(
        "submit", "Run `dataset verify` as a Slurm job array of --tasks shards, each resuming its own results file\n"
                  "(DIR/results-I.jsonl), and a report job after them all (DIR/summary.json, DIR/report.html).\n"
                  "Every node needs zcheck at the same path and the dataset on a shared file system. Example:\n"
                  "  zcheck dataset submit transforms.json --scene mesh.ply --quantity eye-z --tasks 64 --out run1 --wait");
    addDatasetVerifyOptions(submitCommand, submit->verify);
    submitCommand->add_option("--tasks", submit->tasks, "the number of shards (array tasks), 1..100000")
        ->required()
        ->check(CLI::Range(1, 100000));
    submitCommand->add_option("--out", submit->out, "the folder for the scripts, results, logs and report")
        ->type_name("DIR")
        ->required()
        ->check(kNonEmptyPath);
    submitCommand->add_option("--sbatch-arg", submit->sbatchArguments,
                              "an #SBATCH line for both jobs, e.g. --sbatch-arg=--partition=batch (repeatable)");
    submitCommand->add_flag("--wait", submit->wait, "wait for the report job, print the summary and exit with its status");
    submitCommand->add_flag("--dry-run", submit->dryRun, "only write the scripts");
    return [submit] { return runDatasetSubmit(*submit); };
}

}  // namespace zcheck::cli
