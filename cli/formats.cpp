// zcheck formats: the table of camera formats (camera_formats.h) as people and programs read
// it — the docs' table is this command's output, and the bad-input catalogue builds a case per
// row from its --json.
#include "common.h"

#include "zcheck/camera_formats.h"
#include "zcheck/depth_map_formats.h"

#include <nlohmann/json.hpp>

#include <iostream>

namespace zcheck::cli {

namespace {

nlohmann::json formatsJson()
{
    nlohmann::json rows = nlohmann::json::array();
    for (const CameraFormat* format : cameraFormats())
        rows.push_back({{"name", format->name},
                        {"aliases", format->aliases},
                        {"title", format->title},
                        {"extensions", format->extensions},
                        {"files", format->files},
                        {"example", format->example},
                        {"priority", format->priority},
                        {"max_bytes", format->input.maxBytes},
                        {"writes", format->write != nullptr},
                        {"writes_folder", format->writesFolder},
                        {"dataset_source", format->datasetSource},
                        {"names_depth_maps", format->namesDepthMaps}});
    nlohmann::json maps = nlohmann::json::array();
    for (const DepthMapFormat* format : depthMapFormats())
        maps.push_back({{"name", format->name},
                        {"title", format->title},
                        {"extensions", format->extensions},
                        {"writes", format->write != nullptr},
                        {"writes_several_quantities", format->writesSeveral},
                        {"holds", format->holds}});
    return {{"camera_formats", rows}, {"depth_map_formats", maps}};
}

}  // namespace

Command addFormatsCommand(CLI::App& app)
{
    auto json = std::make_shared<bool>(false);
    CLI::App* command = app.add_subcommand(
        "formats", "List the file formats zcheck reads and writes. Camera files: the name --camera-format and --to\n"
                   "take, what its files look like, a --camera reference with its frame, whether `zcheck camera --to`\n"
                   "writes it and whether it is a dataset source. Depth maps: read by their first bytes, written by\n"
                   "their extension (export -o). A file's format is always told by its content.");
    command->add_flag("--json", *json, "the table as JSON (one object per format, with its size limit and detection order)");
    return {command, [json] {
                if (*json) {
                    loadAllDepthMapFormats();  // the image plugin's formats too
                    std::cout << formatsJson().dump(2) << "\n";
                } else {
                    std::cout << cameraFormatTable() << "\n" << depthMapFormatTable();
                }
                return kExitConsistent;
            }};
}

}  // namespace zcheck::cli
