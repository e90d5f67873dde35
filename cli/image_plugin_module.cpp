// libzcheck_images.so: the plugin that carries OpenImageIO for the command line (image_plugin.h).
#include "image_plugin.h"

extern "C" __attribute__((visibility("default"))) const zcheck::cli::ImageFunctions* zcheck_image_functions()
{
    static const zcheck::cli::ImageFunctions functions{&zcheck::readDepthMap, &zcheck::writeExr,
                                                       &zcheck::writeQuantityFile};
    return &functions;
}
