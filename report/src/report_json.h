#pragma once
// The JSON pieces of zcheck's reports, shared by `verify --json` (report.cpp) and the dataset
// results (dataset_report.cpp), so that each section is written in one place. Private to
// zcheck::report (nlohmann).
#include "zcheck/checker.h"
#include "zcheck/verify_map.h"

#include <nlohmann/json.hpp>

namespace zcheck::reportjson {

nlohmann::json pixelsJson(const ComparisonReport& c);                      // "pixels": the classes' counts
nlohmann::json depthErrorJson(const ComparisonReport& c);                  // "depth_error"
nlohmann::json unexplainedJson(const ComparisonReport& c, bool samples);  // "unexplained": count, box[, samples]
nlohmann::json depthMapJson(const DepthMapSource& source);                 // "depth_map"
nlohmann::json hypothesisJson(const Hypothesis& h);                        // one entry of "diagnosis"

}  // namespace zcheck::reportjson
