// Built instead of gl_reference.cpp when EGL was not found at configure time.
#include "zcheck/gl_reference.h"

#include <stdexcept>

namespace zcheck::reference {

bool glReferenceAvailable() { return false; }

GlDepthTiming timeGlDepthDraw(const GlDepthInput&, int)
{
    throw std::runtime_error("the llvmpipe reference was not built (install libegl-dev and libgl1-mesa-dri, then rebuild)");
}

}  // namespace zcheck::reference
