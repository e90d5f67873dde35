// The llvmpipe yardstick as a plugin (gl_reference.h): all the zcheck executable sees of it.
#include "zcheck/gl_reference.h"

extern "C" __attribute__((visibility("default"))) const zcheck::reference::GlYardstickFunctions* zcheck_gl_yardstick()
{
    static const zcheck::reference::GlYardstickFunctions functions{&zcheck::reference::timeGlDepthDraw};
    return &functions;
}
