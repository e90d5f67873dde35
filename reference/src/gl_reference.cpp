#include "zcheck/gl_reference.h"

// Only libEGL is linked: every GL entry point comes from eglGetProcAddress, so the types
// and constants are taken from the Khronos header without its prototypes.
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/glcorearb.h>

#include <malloc.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace zcheck::reference {
namespace {

[[noreturn]] void fail(const std::string& step)
{
    throw std::runtime_error("GL reference: " + step);
}

std::string hex(unsigned value)
{
    char text[16];
    std::snprintf(text, sizeof text, "0x%04X", value);
    return text;
}

[[noreturn]] void failEgl(const std::string& step)
{
    fail(step + " (EGL error " + hex(eglGetError()) + ")");
}

// Whether a space-separated extension string lists `name` exactly (not as a prefix).
bool hasExtension(const char* extensions, const char* name)
{
    if (extensions == nullptr) return false;
    const std::size_t length = std::strlen(name);
    for (const char* at = extensions; (at = std::strstr(at, name)) != nullptr; at += length) {
        const bool startsWord = at == extensions || at[-1] == ' ';
        const bool endsWord = at[length] == ' ' || at[length] == '\0';
        if (startsWord && endsWord) return true;
    }
    return false;
}

// Mesa reads these when eglInitialize creates the driver screen, so they must be set first.
void configureMesaEnvironment(int threads)
{
    setenv("LP_NUM_THREADS", std::to_string(threads).c_str(), /*overwrite=*/1);
    setenv("LIBGL_ALWAYS_SOFTWARE", "1", /*overwrite=*/0);
    setenv("GALLIUM_DRIVER", "llvmpipe", /*overwrite=*/0);
}

// Owns the EGL display initialization and the context, and releases them in reverse order.
class EglSession {
public:
    EglSession() = default;
    EglSession(const EglSession&) = delete;
    EglSession& operator=(const EglSession&) = delete;
    ~EglSession()
    {
        if (current_) eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        if (context_ != EGL_NO_CONTEXT) eglDestroyContext(display_, context_);
        if (initialized_) eglTerminate(display_);
    }

    // Surfaceless display, desktop OpenGL core context (4.5, else 3.3) made current with no
    // surface: rendering goes to a framebuffer object only.
    void open()
    {
        const char* clientExtensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
        if (!hasExtension(clientExtensions, "EGL_EXT_platform_base")) fail("EGL_EXT_platform_base missing");
        if (!hasExtension(clientExtensions, "EGL_MESA_platform_surfaceless"))
            fail("EGL_MESA_platform_surfaceless missing");
        const auto getPlatformDisplay =
            reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
        if (getPlatformDisplay == nullptr) fail("eglGetPlatformDisplayEXT not found");

        display_ = getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
        if (display_ == EGL_NO_DISPLAY) failEgl("no EGL display (surfaceless)");
        if (eglInitialize(display_, nullptr, nullptr) != EGL_TRUE) failEgl("eglInitialize (surfaceless)");
        initialized_ = true;

        const char* displayExtensions = eglQueryString(display_, EGL_EXTENSIONS);
        if (!hasExtension(displayExtensions, "EGL_KHR_surfaceless_context"))
            fail("EGL_KHR_surfaceless_context missing");
        if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE) failEgl("eglBindAPI(EGL_OPENGL_API)");

        // Surface type 0 matches every config: no surface is ever created.
        const EGLint configAttributes[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, 0, EGL_NONE};
        EGLConfig config = nullptr;
        EGLint configCount = 0;
        if (eglChooseConfig(display_, configAttributes, &config, 1, &configCount) != EGL_TRUE || configCount < 1)
            failEgl("no EGL config with EGL_OPENGL_BIT");

        for (const auto& [major, minor] : {std::pair{4, 5}, std::pair{3, 3}}) {
            const EGLint contextAttributes[] = {EGL_CONTEXT_MAJOR_VERSION,
                                                major,
                                                EGL_CONTEXT_MINOR_VERSION,
                                                minor,
                                                EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                                EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                                EGL_NONE};
            context_ = eglCreateContext(display_, config, EGL_NO_CONTEXT, contextAttributes);
            if (context_ != EGL_NO_CONTEXT) break;
        }
        if (context_ == EGL_NO_CONTEXT) failEgl("eglCreateContext (OpenGL 4.5 or 3.3 core)");
        if (eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_) != EGL_TRUE)
            failEgl("eglMakeCurrent (surfaceless)");
        current_ = true;
    }

private:
    EGLDisplay display_ = EGL_NO_DISPLAY;
    bool initialized_ = false;
    EGLContext context_ = EGL_NO_CONTEXT;
    bool current_ = false;
};

template <typename Function> void load(Function& function, const char* name)
{
    function = reinterpret_cast<Function>(eglGetProcAddress(name));
    if (function == nullptr) fail(std::string(name) + " not found");
}

// The GL entry points used here. With libglvnd, eglGetProcAddress returns a dispatch stub
// for any gl* name, so a non-null pointer says nothing about support (see supportsClipControl).
struct Gl {
    PFNGLGETERRORPROC GetError;
    PFNGLGETSTRINGPROC GetString;
    PFNGLGETSTRINGIPROC GetStringi;
    PFNGLGETINTEGERVPROC GetIntegerv;
    PFNGLCREATESHADERPROC CreateShader;
    PFNGLSHADERSOURCEPROC ShaderSource;
    PFNGLCOMPILESHADERPROC CompileShader;
    PFNGLGETSHADERIVPROC GetShaderiv;
    PFNGLGETSHADERINFOLOGPROC GetShaderInfoLog;
    PFNGLDELETESHADERPROC DeleteShader;
    PFNGLCREATEPROGRAMPROC CreateProgram;
    PFNGLATTACHSHADERPROC AttachShader;
    PFNGLLINKPROGRAMPROC LinkProgram;
    PFNGLGETPROGRAMIVPROC GetProgramiv;
    PFNGLGETPROGRAMINFOLOGPROC GetProgramInfoLog;
    PFNGLDELETEPROGRAMPROC DeleteProgram;
    PFNGLUSEPROGRAMPROC UseProgram;
    PFNGLGETUNIFORMLOCATIONPROC GetUniformLocation;
    PFNGLUNIFORMMATRIX4FVPROC UniformMatrix4fv;
    PFNGLGENVERTEXARRAYSPROC GenVertexArrays;
    PFNGLBINDVERTEXARRAYPROC BindVertexArray;
    PFNGLDELETEVERTEXARRAYSPROC DeleteVertexArrays;
    PFNGLGENBUFFERSPROC GenBuffers;
    PFNGLBINDBUFFERPROC BindBuffer;
    PFNGLBUFFERDATAPROC BufferData;
    PFNGLDELETEBUFFERSPROC DeleteBuffers;
    PFNGLVERTEXATTRIBPOINTERPROC VertexAttribPointer;
    PFNGLENABLEVERTEXATTRIBARRAYPROC EnableVertexAttribArray;
    PFNGLGENFRAMEBUFFERSPROC GenFramebuffers;
    PFNGLBINDFRAMEBUFFERPROC BindFramebuffer;
    PFNGLFRAMEBUFFERRENDERBUFFERPROC FramebufferRenderbuffer;
    PFNGLCHECKFRAMEBUFFERSTATUSPROC CheckFramebufferStatus;
    PFNGLDELETEFRAMEBUFFERSPROC DeleteFramebuffers;
    PFNGLGENRENDERBUFFERSPROC GenRenderbuffers;
    PFNGLBINDRENDERBUFFERPROC BindRenderbuffer;
    PFNGLRENDERBUFFERSTORAGEPROC RenderbufferStorage;
    PFNGLRENDERBUFFERSTORAGEMULTISAMPLEPROC RenderbufferStorageMultisample;
    PFNGLBLITFRAMEBUFFERPROC BlitFramebuffer;
    PFNGLGETMULTISAMPLEFVPROC GetMultisamplefv;
    PFNGLDELETERENDERBUFFERSPROC DeleteRenderbuffers;
    PFNGLDRAWBUFFERPROC DrawBuffer;
    PFNGLREADBUFFERPROC ReadBuffer;
    PFNGLVIEWPORTPROC Viewport;
    PFNGLENABLEPROC Enable;
    PFNGLDISABLEPROC Disable;
    PFNGLDEPTHFUNCPROC DepthFunc;
    PFNGLDEPTHMASKPROC DepthMask;
    PFNGLCOLORMASKPROC ColorMask;
    PFNGLCLEARDEPTHPROC ClearDepth;
    PFNGLCLIPCONTROLPROC ClipControl;
    PFNGLCLEARPROC Clear;
    PFNGLDRAWELEMENTSPROC DrawElements;
    PFNGLFINISHPROC Finish;
    PFNGLPIXELSTOREIPROC PixelStorei;
    PFNGLREADPIXELSPROC ReadPixels;

    void loadAll()
    {
        load(GetError, "glGetError");
        load(GetString, "glGetString");
        load(GetStringi, "glGetStringi");
        load(GetIntegerv, "glGetIntegerv");
        load(CreateShader, "glCreateShader");
        load(ShaderSource, "glShaderSource");
        load(CompileShader, "glCompileShader");
        load(GetShaderiv, "glGetShaderiv");
        load(GetShaderInfoLog, "glGetShaderInfoLog");
        load(DeleteShader, "glDeleteShader");
        load(CreateProgram, "glCreateProgram");
        load(AttachShader, "glAttachShader");
        load(LinkProgram, "glLinkProgram");
        load(GetProgramiv, "glGetProgramiv");
        load(GetProgramInfoLog, "glGetProgramInfoLog");
        load(DeleteProgram, "glDeleteProgram");
        load(UseProgram, "glUseProgram");
        load(GetUniformLocation, "glGetUniformLocation");
        load(UniformMatrix4fv, "glUniformMatrix4fv");
        load(GenVertexArrays, "glGenVertexArrays");
        load(BindVertexArray, "glBindVertexArray");
        load(DeleteVertexArrays, "glDeleteVertexArrays");
        load(GenBuffers, "glGenBuffers");
        load(BindBuffer, "glBindBuffer");
        load(BufferData, "glBufferData");
        load(DeleteBuffers, "glDeleteBuffers");
        load(VertexAttribPointer, "glVertexAttribPointer");
        load(EnableVertexAttribArray, "glEnableVertexAttribArray");
        load(GenFramebuffers, "glGenFramebuffers");
        load(BindFramebuffer, "glBindFramebuffer");
        load(FramebufferRenderbuffer, "glFramebufferRenderbuffer");
        load(CheckFramebufferStatus, "glCheckFramebufferStatus");
        load(DeleteFramebuffers, "glDeleteFramebuffers");
        load(GenRenderbuffers, "glGenRenderbuffers");
        load(BindRenderbuffer, "glBindRenderbuffer");
        load(RenderbufferStorage, "glRenderbufferStorage");
        load(RenderbufferStorageMultisample, "glRenderbufferStorageMultisample");
        load(BlitFramebuffer, "glBlitFramebuffer");
        load(GetMultisamplefv, "glGetMultisamplefv");
        load(DeleteRenderbuffers, "glDeleteRenderbuffers");
        load(DrawBuffer, "glDrawBuffer");
        load(ReadBuffer, "glReadBuffer");
        load(Viewport, "glViewport");
        load(Enable, "glEnable");
        load(Disable, "glDisable");
        load(DepthFunc, "glDepthFunc");
        load(DepthMask, "glDepthMask");
        load(ColorMask, "glColorMask");
        load(ClearDepth, "glClearDepth");
        load(ClipControl, "glClipControl");
        load(Clear, "glClear");
        load(DrawElements, "glDrawElements");
        load(Finish, "glFinish");
        load(PixelStorei, "glPixelStorei");
        load(ReadPixels, "glReadPixels");
    }

    // Throws naming `step` if any GL error is pending (all pending errors are drained).
    void check(const char* step) const
    {
        GLenum first = GL_NO_ERROR;
        for (GLenum error; (error = GetError()) != GL_NO_ERROR;)
            if (first == GL_NO_ERROR) first = error;
        if (first != GL_NO_ERROR) fail(std::string(step) + " (GL error " + hex(first) + ")");
    }

    bool supportsClipControl() const
    {
        GLint major = 0, minor = 0;
        GetIntegerv(GL_MAJOR_VERSION, &major);
        GetIntegerv(GL_MINOR_VERSION, &minor);
        if (major > 4 || (major == 4 && minor >= 5)) return true;
        GLint extensionCount = 0;
        GetIntegerv(GL_NUM_EXTENSIONS, &extensionCount);
        for (GLint i = 0; i < extensionCount; ++i) {
            const auto* name = reinterpret_cast<const char*>(GetStringi(GL_EXTENSIONS, static_cast<GLuint>(i)));
            if (name != nullptr && std::strcmp(name, "GL_ARB_clip_control") == 0) return true;
        }
        return false;
    }
};

// GL object names, deleted while the context is still current: it is constructed after the
// EglSession and after every function is loaded, so it is destroyed first and can call them
// all. Name 0 is ignored by every glDelete*.
struct GlObjects {
    const Gl& gl;
    GLuint vertexShader = 0, fragmentShader = 0, program = 0;
    GLuint vertexArray = 0, vertexBuffer = 0, indexBuffer = 0;
    GLuint framebuffer = 0, depthRenderbuffer = 0;
    GLuint resolvedFramebuffer = 0, resolvedRenderbuffer = 0;  // multisampling only

    explicit GlObjects(const Gl& functions) : gl(functions) {}
    GlObjects(const GlObjects&) = delete;
    GlObjects& operator=(const GlObjects&) = delete;
    ~GlObjects()
    {
        gl.UseProgram(0);
        gl.DeleteProgram(program);
        gl.DeleteShader(vertexShader);
        gl.DeleteShader(fragmentShader);
        gl.BindVertexArray(0);
        gl.DeleteVertexArrays(1, &vertexArray);
        gl.DeleteBuffers(1, &vertexBuffer);
        gl.DeleteBuffers(1, &indexBuffer);
        gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
        gl.DeleteFramebuffers(1, &framebuffer);
        gl.DeleteRenderbuffers(1, &depthRenderbuffer);
        gl.DeleteFramebuffers(1, &resolvedFramebuffer);
        gl.DeleteRenderbuffers(1, &resolvedRenderbuffer);
    }
};

constexpr const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 p;
uniform mat4 clipFromWorld;
void main() { gl_Position = clipFromWorld * vec4(p, 1.0); }
)";

// Depth only: nothing is written but the depth of the fixed-function depth test.
constexpr const char* kFragmentShader = R"(#version 330 core
void main() {}
)";

GLuint compileShader(const Gl& gl, GLenum stage, const char* source, const char* stageName)
{
    const GLuint shader = gl.CreateShader(stage);
    if (shader == 0) fail(std::string("glCreateShader (") + stageName + ")");
    gl.ShaderSource(shader, 1, &source, nullptr);
    gl.CompileShader(shader);
    GLint compiled = GL_FALSE;
    gl.GetShaderiv(shader, GL_COMPILE_STATUS, &compiled);
    if (compiled != GL_TRUE) {
        char log[512] = {};
        gl.GetShaderInfoLog(shader, sizeof log, nullptr, log);
        gl.DeleteShader(shader);
        fail(std::string("compiling the ") + stageName + " shader: " + log);
    }
    return shader;
}

void validate(const GlDepthInput& input, int repeats)
{
    if (input.positions == nullptr || input.indices == nullptr) throw std::invalid_argument("GL reference: null mesh");
    if (input.width <= 0 || input.height <= 0) throw std::invalid_argument("GL reference: empty viewport");
    if (input.threads < 0) throw std::invalid_argument("GL reference: negative thread count");
    if (input.samples < 0) throw std::invalid_argument("GL reference: negative sample count");
    if (repeats < 0) throw std::invalid_argument("GL reference: negative repeat count");
    if (input.triangleCount > static_cast<std::size_t>(std::numeric_limits<GLsizei>::max()) / 3)
        throw std::invalid_argument("GL reference: too many triangles for one glDrawElements");
    // An out-of-range index would make llvmpipe read past the vertex buffer.
    for (std::size_t i = 0; i < 3 * input.triangleCount; ++i)
        if (input.indices[i] >= input.vertexCount)
            throw std::invalid_argument("GL reference: vertex index out of range");
}

// Compiles and links the depth-only program, makes it current and gives it input's clipFromWorld.
void buildProgram(const Gl& gl, GlObjects& objects, const GlDepthInput& input)
{
    objects.vertexShader = compileShader(gl, GL_VERTEX_SHADER, kVertexShader, "vertex");
    objects.fragmentShader = compileShader(gl, GL_FRAGMENT_SHADER, kFragmentShader, "fragment");
    objects.program = gl.CreateProgram();
    if (objects.program == 0) fail("glCreateProgram");
    gl.AttachShader(objects.program, objects.vertexShader);
    gl.AttachShader(objects.program, objects.fragmentShader);
    gl.LinkProgram(objects.program);
    GLint linked = GL_FALSE;
    gl.GetProgramiv(objects.program, GL_LINK_STATUS, &linked);
    if (linked != GL_TRUE) {
        char log[512] = {};
        gl.GetProgramInfoLog(objects.program, sizeof log, nullptr, log);
        fail(std::string("linking the program: ") + log);
    }
    gl.UseProgram(objects.program);
    const GLint clipFromWorldLocation = gl.GetUniformLocation(objects.program, "clipFromWorld");
    if (clipFromWorldLocation < 0) fail("uniform clipFromWorld not found");
    std::array<GLfloat, 16> clipFromWorld{};
    for (std::size_t i = 0; i < clipFromWorld.size(); ++i)
        clipFromWorld[i] = static_cast<GLfloat>(input.clipFromWorld[i]);
    gl.UniformMatrix4fv(clipFromWorldLocation, 1, GL_FALSE, clipFromWorld.data()); // column-major, as given
    gl.check("building the shader program");
}

// Uploads the mesh once, into buffers that the vertex array records; the vertex array stays bound.
void uploadMesh(const Gl& gl, GlObjects& objects, const GlDepthInput& input)
{
    gl.GenVertexArrays(1, &objects.vertexArray);
    gl.BindVertexArray(objects.vertexArray);
    gl.GenBuffers(1, &objects.vertexBuffer);
    gl.BindBuffer(GL_ARRAY_BUFFER, objects.vertexBuffer);
    gl.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(3 * input.vertexCount * sizeof(float)), input.positions,
                  GL_STATIC_DRAW);
    gl.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
    gl.EnableVertexAttribArray(0);
    gl.GenBuffers(1, &objects.indexBuffer);
    gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, objects.indexBuffer); // recorded in the vertex array
    gl.BufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(3 * input.triangleCount * sizeof(std::uint32_t)),
                  input.indices, GL_STATIC_DRAW);
    gl.check("uploading the mesh");
}

// A complete depth-only framebuffer of input's size (`samples` > 1: multisampled), left bound; `what` names the step.
void createDepthTarget(const Gl& gl, const GlDepthInput& input, GLenum depthFormat, int samples, GLuint& renderbuffer,
                       GLuint& framebuffer, const char* what)
{
    gl.GenRenderbuffers(1, &renderbuffer);
    gl.BindRenderbuffer(GL_RENDERBUFFER, renderbuffer);
    if (samples > 1)
        gl.RenderbufferStorageMultisample(GL_RENDERBUFFER, samples, depthFormat, input.width, input.height);
    else
        gl.RenderbufferStorage(GL_RENDERBUFFER, depthFormat, input.width, input.height);
    gl.GenFramebuffers(1, &framebuffer);
    gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, renderbuffer);
    gl.DrawBuffer(GL_NONE);
    gl.ReadBuffer(GL_NONE);
    gl.check(what);
    if (const GLenum status = gl.CheckFramebufferStatus(GL_FRAMEBUFFER); status != GL_FRAMEBUFFER_COMPLETE)
        fail(std::string(what) + ": framebuffer incomplete (status " + hex(status) + ")");
}

// The depth buffer's format. Reversed-Z keeps its precision only with a float buffer.
GLenum depthFormatOf(const GlDepthInput& input) { return input.reversedZ ? GL_DEPTH_COMPONENT32F : GL_DEPTH_COMPONENT24; }

// The framebuffer drawn into, left bound, and with multisampling first the single-sample one it is resolved into.
void createDepthTargets(const Gl& gl, GlObjects& objects, const GlDepthInput& input)
{
    const GLenum depthFormat = depthFormatOf(input);
    if (input.samples > 1)
        createDepthTarget(gl, input, depthFormat, 1, objects.resolvedRenderbuffer, objects.resolvedFramebuffer,
                          "creating the resolved depth framebuffer");
    createDepthTarget(gl, input, depthFormat, input.samples, objects.depthRenderbuffer, objects.framebuffer,
                      "creating the depth framebuffer");
}

// The bound framebuffer's sample positions as GL reports them (GlDepthTiming::samplePositions).
std::vector<std::array<float, 2>> samplePositionsOf(const Gl& gl)
{
    std::vector<std::array<float, 2>> positions;
    GLint samples = 0;
    gl.GetIntegerv(GL_SAMPLES, &samples);
    for (GLint k = 0; k < samples; ++k) {
        std::array<GLfloat, 2> position{};
        gl.GetMultisamplefv(GL_SAMPLE_POSITION, GLuint(k), position.data());
        positions.push_back({position[0], position[1]});
    }
    gl.check("querying the sample positions");
    return positions;
}

// Fixed-function state for a depth-only draw in input's depth convention (zeroToOne: glClipControl).
void setDepthState(const Gl& gl, const GlDepthInput& input, bool zeroToOne)
{
    gl.Viewport(0, 0, input.width, input.height);
    gl.ColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    gl.Disable(GL_CULL_FACE);
    gl.Enable(GL_DEPTH_TEST);
    gl.DepthMask(GL_TRUE);
    if (zeroToOne) gl.ClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
    gl.DepthFunc(input.reversedZ ? GL_GREATER : GL_LESS);
    gl.ClearDepth(input.reversedZ ? 0.0 : 1.0);
    gl.check("setting the depth state");
}

// One draw of the whole mesh into the bound framebuffer, cleared first and finished.
void drawMesh(const Gl& gl, const GlDepthInput& input)
{
    gl.Clear(GL_DEPTH_BUFFER_BIT);
    gl.DrawElements(GL_TRIANGLES, static_cast<GLsizei>(3 * input.triangleCount), GL_UNSIGNED_INT, nullptr);
    gl.Finish();
}

// The wall time of step() in milliseconds.
template <class Step>
double millisecondsOf(Step step)
{
    const auto start = std::chrono::steady_clock::now();
    step();
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// One warm-up draw, then `repeats` timed ones: each one's wall time in milliseconds (GlDepthTiming::drawMs).
std::vector<double> timeDraws(const Gl& gl, const GlDepthInput& input, int repeats)
{
    drawMesh(gl, input);  // warm-up: llvmpipe generates its shader and rasterizer code with LLVM here
    gl.check("warm-up draw");
    std::vector<double> drawMs;
    drawMs.reserve(static_cast<std::size_t>(repeats));
    for (int repeat = 0; repeat < repeats; ++repeat) drawMs.push_back(millisecondsOf([&] { drawMesh(gl, input); }));
    gl.check("timed draws");
    return drawMs;
}

// `repeats` timed draws, each into a depth buffer of its own made for it (GlDepthTiming::coldDrawMs),
// after the warm ones: the framebuffer drawn before is bound again at the end.
std::vector<double> timeColdDraws(const Gl& gl, const GlObjects& objects, const GlDepthInput& input, int repeats)
{
    std::vector<double> drawMs;
    drawMs.reserve(static_cast<std::size_t>(repeats));
    for (int repeat = 0; repeat < repeats; ++repeat) {
#ifdef __GLIBC__
        malloc_trim(0);  // memory the C library kept from freed buffers given back: the new one is untouched
#endif
        GLuint renderbuffer = 0, framebuffer = 0;
        drawMs.push_back(millisecondsOf([&] {
            createDepthTarget(gl, input, depthFormatOf(input), input.samples, renderbuffer, framebuffer,
                              "creating a new depth framebuffer");
            drawMesh(gl, input);
        }));
        gl.BindFramebuffer(GL_FRAMEBUFFER, objects.framebuffer);
        gl.DeleteFramebuffers(1, &framebuffer);
        gl.DeleteRenderbuffers(1, &renderbuffer);
        gl.check("timed draws into new depth buffers");
    }
    return drawMs;
}

// The multisampled depth blitted into the single-sample framebuffer, which is left bound for reading.
void resolveMultisampledDepth(const Gl& gl, const GlObjects& objects, const GlDepthInput& input)
{
    // A multisampled buffer is resolved as an application does it, by a blit (which sample, or
    // what blend, a depth resolve keeps is the implementation's choice).
    gl.BindFramebuffer(GL_READ_FRAMEBUFFER, objects.framebuffer);
    gl.BindFramebuffer(GL_DRAW_FRAMEBUFFER, objects.resolvedFramebuffer);
    gl.BlitFramebuffer(0, 0, input.width, input.height, 0, 0, input.width, input.height, GL_DEPTH_BUFFER_BIT, GL_NEAREST);
    gl.BindFramebuffer(GL_FRAMEBUFFER, objects.resolvedFramebuffer);
    gl.check("resolving the multisampled depth");
}

// The bound framebuffer's depth, read back with row 0 the top of the image (GlDepthTiming::depth).
std::vector<float> readBackDepth(const Gl& gl, const GlDepthInput& input)
{
    // GL's rows run bottom-up; the result's row 0 is the top of the image.
    const auto width = static_cast<std::size_t>(input.width);
    const auto height = static_cast<std::size_t>(input.height);
    std::vector<float> bottomUp(width * height);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl.ReadPixels(0, 0, input.width, input.height, GL_DEPTH_COMPONENT, GL_FLOAT, bottomUp.data());
    gl.check("reading back the depth");
    std::vector<float> depth(width * height);
    for (std::size_t row = 0; row < height; ++row)
        std::memcpy(&depth[row * width], &bottomUp[(height - 1 - row) * width], width * sizeof(float));
    return depth;
}

} // namespace

GlDepthTiming timeGlDepthDraw(const GlDepthInput& input, int repeats)
{
    validate(input, repeats);
    configureMesaEnvironment(input.threads);

    EglSession session;
    session.open();
    Gl gl{};
    gl.loadAll();
    GlObjects objects(gl);
    gl.check("creating the context");

    GlDepthTiming timing;
    if (const auto* renderer = reinterpret_cast<const char*>(gl.GetString(GL_RENDERER))) timing.renderer = renderer;

    const bool zeroToOne = input.reversedZ || input.zeroToOne;
    if (zeroToOne && !gl.supportsClipControl()) fail("glClipControl unsupported (needs GL 4.5 or GL_ARB_clip_control)");

    buildProgram(gl, objects, input);
    uploadMesh(gl, objects, input);
    createDepthTargets(gl, objects, input);
    if (input.samples > 1) timing.samplePositions = samplePositionsOf(gl);
    setDepthState(gl, input, zeroToOne);
    timing.drawMs = timeDraws(gl, input, repeats);
    timing.coldDrawMs = timeColdDraws(gl, objects, input, repeats);
    if (input.samples > 1) resolveMultisampledDepth(gl, objects, input);
    timing.depth = readBackDepth(gl, input);
    return timing;
}

} // namespace zcheck::reference
