// libzcheck_images.so: the plugin that carries OpenImageIO for the command line (image_plugin.h).
// It holds its own copy of the depth-map code; its rows are registered in the executable's table.
#include "image_plugin.h"

#include "zcheck/image_io.h"

extern "C" __attribute__((visibility("default"))) const zcheck::cli::ImageFunctions* zcheck_image_functions()
{
    static const std::vector<const zcheck::DepthMapFormat*> formats = zcheck::imageIoDepthMapFormats();
    static const zcheck::cli::ImageFunctions functions{formats.data(), formats.size(), &zcheck::writeExr};
    return &functions;
}
