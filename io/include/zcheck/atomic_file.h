#pragma once
// Output files: every file a run writes appears all together or not at all.
//
// A run registers its inputs and its outputs with an OutputFiles before it computes anything,
// so that a bad output path fails in milliseconds: an empty path, a directory, a folder
// that does not exist or cannot be written, an output that is one of the run's inputs, or
// two outputs on one path are refused with an Error naming the option and the path. Each
// output is then written into a temporary sibling (same folder, same extension, for writers
// that choose a format by it), checked and synced; commit() renames them all into place.
// A run that fails before commit() leaves every old file unchanged and no temporary behind.
//
//   OutputFiles outputs;
//   outputs.addInput(depthMapPath);
//   outputs.add(plyPath, "-o");                  // validated now
//   ... compute ...
//   outputs.write(plyPath, [&](const std::string& temporary) { writePointCloudPly(temporary, ...); });
//   outputs.commit();
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace zcheck {

class OutputFiles {
public:
    OutputFiles() = default;
    OutputFiles(const OutputFiles&) = delete;
    OutputFiles& operator=(const OutputFiles&) = delete;
    ~OutputFiles();  // removes the temporaries of an uncommitted run (and a folder it created)

    // A file the run reads: no output may be the same file.
    void addInput(const std::string& path);
    // Registers an output file, named by `option` in messages ("-o", "--preview", ...).
    void add(const std::string& path, const std::string& option);
    // Registers a folder that will hold outputs (check --out DIR): an existing folder, or a
    // new one whose parent exists; it is created when the first file is written into it.
    void addFolder(const std::string& path, const std::string& option);

    // Writes a registered output through `writer` into its temporary; any Error names `path`.
    void write(const std::string& path, const std::function<void(const std::string& temporaryPath)>& writer);
    void writeText(const std::string& path, std::string_view contents);
    // Renames every written temporary onto its path. Every registered output must have been written.
    void commit();

private:
    struct Output {
        std::string path, option, temporary;
        bool written = false;
    };
    Output& registered(const std::string& path);
    void checkNotInput(const std::string& path, const std::string& option) const;

    std::vector<std::string> inputs_;
    std::vector<Output> outputs_;
    std::vector<std::string> plannedFolders_;  // addFolder's, perhaps not yet existing
    std::vector<std::string> createdFolders_;  // made by write(), removed again on failure
    bool committed_ = false;
};

// Writes `bytes` to `path` (created or truncated), checking every write, the fsync and the
// close; throws Error naming `path` (ENOSPC: "no space left on device").
void writeFileBytes(const std::string& path, std::string_view bytes);

// One output on its own: an OutputFiles of one file.
void writeAtomically(const std::string& path, const std::function<void(const std::string& temporaryPath)>& write);
void writeTextFileAtomically(const std::string& path, const std::string& contents);

}  // namespace zcheck
