#pragma once
// Output files are written atomically: into a temporary sibling, then renamed over the
// target. A failed or interrupted run never leaves a half-written file and never destroys
// an existing one.
#include <functional>
#include <string>

namespace zcheck {

// Calls write(temporaryPath) — the temporary keeps the target's extension, for writers that
// choose a format by it — then renames the temporary onto `path`. On any failure the
// temporary is removed and Error names `path`.
void writeAtomically(const std::string& path, const std::function<void(const std::string& temporaryPath)>& write);

void writeTextFileAtomically(const std::string& path, const std::string& contents);

}  // namespace zcheck
