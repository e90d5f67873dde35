#pragma once
// A speed yardstick: times a depth-only OpenGL draw of a triangle mesh on Mesa's llvmpipe
// (software rasterizer), headless through EGL's surfaceless platform.
//
// This is not part of the check. A benchmark uses it to put zcheck's own rasterization time
// next to that of a mature CPU rasterizer drawing the same mesh at the same resolution.
//
// What is timed, per repeat (wall time, std::chrono::steady_clock):
//   glClear(GL_DEPTH_BUFFER_BIT); glDrawElements(all triangles); glFinish();
// into the one depth buffer every repeat draws into (warm: its memory touched before), and
// then, as many times again, the same into a depth buffer made for that draw, its making
// (glRenderbufferStorage, the framebuffer) timed too, with the C library's free memory given
// back before it (malloc_trim, untimed): a first frame's buffer, memory the process has not
// touched, as a cold check's buffers are (the shaders and the mesh stay as they were).
// What is not timed: creating the EGL display and context, compiling and linking the
// shaders, uploading the mesh (done once, before any draw), one warm-up draw (llvmpipe
// compiles its shader variants with LLVM on the first draw), and reading the depth back.
//
// Environment and threads:
//   - LP_NUM_THREADS is set to `threads` (overriding any value already set, since choosing
//     the thread count is the point); LIBGL_ALWAYS_SOFTWARE=1 and GALLIUM_DRIVER=llvmpipe
//     are set only when unset, so a user's choice is kept (GALLIUM_DRIVER=softpipe would
//     time softpipe: GlDepthTiming::renderer says which driver actually drew).
//   - Mesa reads LP_NUM_THREADS when it creates the driver screen, in eglInitialize. Each
//     call initializes and terminates its own display, which destroys the screen, so each
//     call's `threads` takes effect (checked with Mesa 22.3: a second call in one process
//     runs with its own count). Were the surfaceless display kept initialized elsewhere in
//     the process, eglInitialize would reuse the first screen and its thread count.
//   - setenv is not thread-safe: call this while no other thread reads the environment.
//   - llvmpipe's rasterizer threads are in addition to the calling thread, which does the
//     vertex processing and binning; threads = 0 rasterizes on the calling thread too. With
//     ~1M small triangles the calling thread's share dominates, so more threads help little.
//   - The calling thread is left with no current EGL context and EGL_OPENGL_API bound; the
//     surfaceless display is terminated at the end, so do not call this while the same
//     thread or process uses that display for something else.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace zcheck::reference {

struct GlDepthInput {
    const float* positions = nullptr;      // xyz per vertex, world space
    std::size_t vertexCount = 0;
    const std::uint32_t* indices = nullptr;  // 3 per triangle, each < vertexCount
    std::size_t triangleCount = 0;
    // Column-major (GLM layout). Standard OpenGL clip space (-w ≤ z ≤ w) unless reversedZ or
    // zeroToOne says otherwise.
    std::array<double, 16> clipFromWorld{};
    int width = 0;
    int height = 0;
    // Clip-space 0 ≤ z ≤ w with the near plane at z = w: glClipControl(GL_LOWER_LEFT,
    // GL_ZERO_TO_ONE), depth cleared to 0, GL_GREATER, 32-bit float depth buffer.
    // Implies zeroToOne. Otherwise: depth cleared to 1, GL_LESS, 24-bit depth buffer.
    bool reversedZ = false;
    // Clip-space 0 ≤ z ≤ w (Direct3D/Vulkan style), near at 0: glClipControl(GL_LOWER_LEFT,
    // GL_ZERO_TO_ONE), GL_LESS, depth cleared to 1.
    bool zeroToOne = false;
    int threads = 1;  // LP_NUM_THREADS for llvmpipe (≥ 0)
    // > 1: draw into a multisampled depth buffer of this many samples, and resolve it into a
    // single-sample one with glBlitFramebuffer (GL_NEAREST), as an application reading back
    // an MSAA depth buffer does; which sample the resolve keeps is the implementation's choice.
    int samples = 0;
};

struct GlDepthTiming {
    std::vector<double> drawMs;      // one per repeat: glClear + glDrawElements + glFinish (warm)
    std::vector<double> coldDrawMs;  // one per repeat: the same into a new depth buffer, its making timed
    std::string renderer;            // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
    // The depth buffer the warm draws drew into, width*height values in [0, 1], row 0 = top row
    // of the image (glReadPixels' bottom-up order flipped).
    std::vector<float> depth;
    // Multisampling: each sample's position in the pixel as GL reports it (glGetMultisamplefv,
    // GL_SAMPLE_POSITION): x right and y up from the pixel's lower-left corner, in [0, 1].
    std::vector<std::array<float, 2>> samplePositions;
};

// True when this module was compiled in; the build compiles it only when EGL is found.
// Draws the mesh once untimed, then `repeats` (≥ 0) timed times into the same depth buffer and
// as many into new ones, and reads back the first buffer's depth. Throws std::invalid_argument
// for bad input, and std::runtime_error with a one-line message naming the failing EGL/GL step
// (e.g. "no EGL display (surfaceless)", "EGL_MESA_platform_surfaceless missing",
// "glClipControl unsupported (needs GL 4.5 or GL_ARB_clip_control)"). Every EGL/GL resource is
// released on both paths.
GlDepthTiming timeGlDepthDraw(const GlDepthInput& input, int repeats);

// What the plugin libzcheck_gl_yardstick.so offers `zcheck bench --reference`, which loads it
// only then: the zcheck executable links no GL library.
struct GlYardstickFunctions {
    GlDepthTiming (*timeDraw)(const GlDepthInput& input, int repeats);  // timeGlDepthDraw
};

}  // namespace zcheck::reference

// The plugin's one entry point.
extern "C" const zcheck::reference::GlYardstickFunctions* zcheck_gl_yardstick();
