// zcheck — the command line: a dispatcher. Each subcommand lives in its own file (check.cpp,
// matrices.cpp, precision.cpp, unproject.cpp, export.cpp, verify.cpp, suite.cpp, bench.cpp)
// and calls the libraries. Exit status: 0 consistent, 1 inconsistent, 2 usage or input error, 3 internal
// failure (out of memory, a library error); errors are one line on stderr.
#include "common.h"
#include "image_plugin.h"

#include "zcheck/error.h"
#include "zcheck/version.h"

#include <iostream>

int main(int argc, char** argv)
{
    using namespace zcheck::cli;
    using zcheck::Error;
    loadImageFormatsWhenNeeded();
    CLI::App app{"zcheck proves a graphics transform chain correct by computing every pixel's depth twice —\n"
                 "by ray casting through the camera's definition (Embree) and by rasterizing forward through\n"
                 "view, projection, clipping, divide and viewport — and demanding agreement.",
                 "zcheck"};
    app.require_subcommand(1);
    app.set_version_flag("--version", std::string(zcheck::kVersion));
    const Command commands[] = {addCheckCommand(app),  addMatricesCommand(app), addPrecisionCommand(app),
                                addUnprojectCommand(app), addRemapCommand(app), addExportCommand(app), addVerifyCommand(app),
                                addSuiteCommand(app),  addBenchCommand(app),    addCameraCommand(app),
                                addDatasetCommand(app),  addFormatsCommand(app)};

    // CLI11 says only "a subcommand is required" for a misspelt one: name it.
    if (argc > 1 && argv[1][0] != '-') {
        std::string names;
        bool found = false;
        for (const CLI::App* command : app.get_subcommands({})) {
            found = found || command->get_name() == argv[1];
            names += (names.empty() ? "" : ", ") + command->get_name();
        }
        if (!found) {
            std::cerr << "zcheck: error: unknown command '" << argv[1] << "' (expected one of: " << names
                      << "; see 'zcheck --help')\n";
            return kExitUsage;
        }
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::cerr << "zcheck: error: " << e.what() << " (see 'zcheck --help')\n";
        return kExitUsage;
    }

    try {
        for (const Command& command : commands)
            if (command.app->parsed()) return command.run();
    } catch (const zcheck::Error& e) {
        std::cerr << "zcheck: error: " << e.what() << "\n";
        return kExitUsage;
    } catch (const std::bad_alloc&) {
        std::cerr << "zcheck: internal error: out of memory (the mesh or the image is too large for this machine)\n";
        return kExitInternal;
    } catch (const std::exception& e) {
        std::string what = e.what();
        for (char& c : what)
            if (c == '\n' || c == '\r') c = ' ';
        std::cerr << "zcheck: internal error: " << what << "\n";
        return kExitInternal;
    }
    return kExitInternal;
}
