#pragma once
// Dataset results (library zcheck::report): the JSON Lines `zcheck dataset verify` appends, one
// line per frame as it finishes, read back (to resume a run, or to report), merged and summed up.
//
// A record (one line):
//   frame, index, of        the frame's name, its index in the dataset, the dataset's size
//   source, scene           the dataset and the frame's scene
//   consistent              true only for a verified, consistent frame
//   error                   null, or the one-line message of a frame that could not be verified
//   seconds                 the frame's wall time (reading, verifying, diagnosing)
//   depth_map               file, quantity, channel, scale, offset, miss, declared (as `verify --json`)
//   pixels, depth_error     as `verify --json`
//   unexplained             count and bounding_box (no samples)
//   camera                  convention, type, width, height, near, far of the camera used
//   warnings                what was assumed (near and far from the scene, a scale a file implied)
//   diagnosis               with --diagnose, for an inconsistent frame: the hypotheses that make
//                           it consistent (or consistent but for edge pixels), best first, each
//                           as in `verify --json`; `closest` names the best when none does
#include "zcheck/dataset.h"

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace zcheck {

// One line of JSON, without its newline.
std::string frameRecordJson(const FrameResult& result);

// A record read back: what merging and summing up need.
struct FrameRecord {
    std::size_t index = 0, of = 0;
    std::string frame, source, scene, depth, quantity;
    std::string channel, miss;                // the reading, as recorded (scale 0: none)
    double scale = 0, offset = 0;
    MapAccuracy accuracy;                     // what the reading declared
    std::string convention, projection;       // the camera used
    double near = 0, far = 0;
    bool consistent = false;
    std::string error;                       // "" when verified
    std::int64_t unexplained = 0, depthErrors = 0, compared = 0;
    double maxOverTolerance = 0, maxRelativeEyeZ = 0, p99RelativeEyeZ = 0;
    std::vector<std::string> explainedBy;    // hypothesis names that make it consistent, best first
    std::vector<std::string> explanations;   // their explanations
    std::string closest;                     // the best hypothesis when none explains it
    std::string declaredRefused;             // why the reading's declarations were refused ("" if not)
    std::vector<std::string> warnings;       // what was assumed for it (a scale the camera file implies, near and far)
    double seconds = 0;
    std::string file;                        // the results file and line it was read from
    std::size_t line = 0;
};

// A record line (frameRecordJson) as `dataset report` reads it back; `where` names it in errors.
FrameRecord frameRecordOf(const std::string& recordJson, const std::string& where);

struct ResultsFile {
    std::string path;
    std::vector<FrameRecord> records;
    std::uint64_t completeBytes = 0;  // the bytes up to the end of the last complete line
    bool torn = false;                // a last line without its newline (a killed writer) was dropped
};

// Reads a results file: every complete line must be a record (Error naming the file and line);
// a last line without its newline is a torn write: not read, and `torn` says so.
ResultsFile readResults(const std::string& path);

// The results of one dataset, merged: duplicates (a frame recorded twice, in one file or two)
// and missing frames found, every frame counted once (its first record), failures named.
struct DatasetSummary {
    std::string source;
    std::size_t frames = 0;                            // the dataset's size
    std::size_t recorded = 0;                          // distinct frames with a record
    std::size_t consistent = 0, inconsistent = 0, errors = 0;
    std::vector<std::size_t> missing;                  // indices without a record
    std::vector<std::string> duplicates;               // "frame 'x' (index 3): a.jsonl line 4, b.jsonl line 9"
    std::map<std::string, std::size_t> byMistake;      // best explaining hypothesis → inconsistent frames
    std::string diagnosis;                             // one sentence when most frames fail the same way; ""
    std::vector<std::pair<std::string, std::size_t>> notes;  // what was assumed, and for how many frames, most first
    std::vector<FrameRecord> worst;                    // failing frames, worst first (at most 12)
    std::vector<FrameRecord> all;                      // every counted record, by index
    double seconds = 0;                                // the frames' wall time, summed
};
// Throws Error for records of different datasets (their sources or sizes differ) or none at all.
DatasetSummary summarizeResults(const std::vector<ResultsFile>& files);

std::string datasetSummaryText(const DatasetSummary& summary);
// "CONSISTENT" (every frame of a non-empty dataset), "INCONSISTENT", or "INCOMPLETE" (frames missing).
std::string datasetVerdict(const DatasetSummary& summary);
// source, frames, recorded, consistent, inconsistent, errors, missing, duplicates, by_mistake,
// verdict (datasetVerdict), diagnosis (the sentence, or null), notes ({note, frames}: what was
// assumed, most frames first), worst: what the results say, not how long they took (so that a sharded run and a
// single process give the same document).
std::string datasetSummaryJson(const DatasetSummary& summary);

// A failing frame's pictures for the HTML report, as data: URIs: the map's depth (viridis), the
// error heatmap and the coverage classes (report_images.h); or why they could not be made.
struct FramePictures {
    std::string truth, depth, heatmap, classes;  // truth and depth: eye-z on one colour range
    std::string unavailable;
    // None, and why.
    static FramePictures none(std::string why)
    {
        FramePictures out;
        out.unavailable = std::move(why);
        return out;
    }
};
FramePictures framePictures(const VerifiedMap& verified);
// The pictures of a record's frame, made by verifying it again (the command line does it from
// the record's source, scene and reading).
using FramePictureMaker = std::function<FramePictures(const FrameRecord&)>;

// A self-contained page: the summary, a histogram of the frames' p99 relative eye-z error,
// the mistakes found, and the worst frames with their pictures.
std::string datasetReportHtml(const DatasetSummary& summary, const FramePictureMaker& pictures);

}  // namespace zcheck
