// zcheck matrices: a camera's transforms as JSON.
#include "common.h"

#include "zcheck/camera_file.h"

#include <iostream>

namespace zcheck::cli {

Command addMatricesCommand(CLI::App& app)
{
    struct Options {
        CameraOptions camera;
    };
    auto o = std::make_shared<Options>();
    CLI::App* command = app.add_subcommand(
        "matrices", "Print a camera's transforms as JSON: eye_from_world, world_from_eye, clip_from_eye,\n"
                    "eye_from_clip, clip_from_world, window_from_ndc, ndc_from_window (4 rows of 4, column\n"
                    "vectors p' = M·p), and a 'native' block in the convention's own form (row vectors for\n"
                    "direct3d).");
    addCameraOptions(command, o->camera, cameraFileHelp());
    command->get_option("--camera")->required();
    return {command, [o] {
                std::cout << matricesJsonText(Camera(cameraSpecFrom(o->camera))) << "\n";
                return kExitConsistent;
            }};
}

}  // namespace zcheck::cli
