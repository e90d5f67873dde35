#pragma once
// The JSON pieces of zcheck's reports, shared by `verify --json` (report.cpp) and the dataset
// results (dataset_report.cpp), so that each section is written in one place. Private to
// zcheck::report (nlohmann).
#include "zcheck/checker.h"
#include "zcheck/verify_map.h"

#include <nlohmann/json.hpp>

namespace zcheck::reportjson {

// Each names the truth's partner as the report does (CheckReport::secondRoute): "raster_only",
// "raster_window_depth" in check's; "map_only", "map_window_depth" in verify's.
nlohmann::json pixelsJson(const CheckReport& r);                      // "pixels": the classes' counts
nlohmann::json depthErrorJson(const CheckReport& r);                  // "depth_error"
nlohmann::json unexplainedJson(const CheckReport& r, bool samples);  // "unexplained": count, box[, samples]
nlohmann::json mapErrorsJson(const CheckReport& r);                   // "map_errors" (verify; null: nothing compared)
nlohmann::json outOfRangeJson(const CheckReport& r);                  // "out_of_range" (verify)
nlohmann::json declaredRefusedJson(const CheckReport& r);             // "declared_accuracy_refused" (verify): why, or null
nlohmann::json depthMapJson(const DepthMapSource& source);                 // "depth_map"
nlohmann::json hypothesisJson(const Hypothesis& h);                        // one entry of "diagnosis"
// A pixel class's name as a report says it: "raster-only" is "map-only" in verify's (`second`).
std::string className(PixelClass c, const std::string& second);

}  // namespace zcheck::reportjson
