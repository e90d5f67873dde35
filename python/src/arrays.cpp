// numpy arrays in and out: shapes and dtypes named in messages, matrices written for column
// vectors (M[r, c], p' = M·p, while GLM stores m[c][r]), and depth maps given as arrays.
#include "bindings.h"

#include "zcheck/depth_map.h"
#include "zcheck/pose.h"

#include <cmath>

namespace zcheck::python {

std::string shapeText(const py::array& a)
{
    std::string text = "(";
    for (py::ssize_t i = 0; i < a.ndim(); ++i) text += (i ? ", " : "") + std::to_string(a.shape(i));
    return text + (a.ndim() == 1 ? ",)" : ")");
}

std::string dtypeText(const py::array& a) { return py::str(py::handle(a.dtype())).cast<std::string>(); }

py::array numericArray(py::handle object, const std::string& what)
{
    if (object.is_none()) fail(what + " is missing");
    py::array a = py::array::ensure(object);
    if (!a) fail(what + " must be an array of numbers");
    const char kind = a.dtype().kind();
    if (kind != 'f' && kind != 'i' && kind != 'u')
        fail(what + " must be an array of numbers (float or integer), got dtype " + dtypeText(a));
    return a;
}

DoubleArray asDoubles(const py::array& a) { return DoubleArray::ensure(a); }

glm::dmat4 matrixFromArray(py::handle object, const std::string& what, bool allow3x4)
{
    const py::array a = numericArray(object, what);
    const bool ok = a.ndim() == 2 && a.shape(1) == 4 && (a.shape(0) == 4 || (allow3x4 && a.shape(0) == 3));
    if (!ok)
        fail(what + " must be a " + std::string(allow3x4 ? "4x4 or 3x4" : "4x4") + " matrix, got shape " + shapeText(a));
    const DoubleArray d = asDoubles(a);
    const auto v = d.unchecked<2>();
    glm::dmat4 m(1.0);
    for (py::ssize_t r = 0; r < d.shape(0); ++r)
        for (int c = 0; c < 4; ++c) {
            if (!std::isfinite(v(r, c)))
                fail(what + "[" + std::to_string(r) + ", " + std::to_string(c) + "] is not finite (" +
                     formatNumber(v(r, c)) + ")");
            m[c][int(r)] = v(r, c);
        }
    if (d.shape(0) == 4 && allow3x4 && !hasRigidLastRow(m))
        fail(what + " must have the last row 0 0 0 1 (a rigid transform for column vectors)");
    return m;
}

py::array_t<double> arrayFromMatrix(const glm::dmat4& m)
{
    py::array_t<double> out({py::ssize_t(4), py::ssize_t(4)});
    auto v = out.mutable_unchecked<2>();
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) v(r, c) = m[c][r];
    return out;
}

py::array_t<double> arrayFromVec3(const glm::dvec3& p)
{
    py::array_t<double> out(py::ssize_t(3));
    auto v = out.mutable_unchecked<1>();
    for (int i = 0; i < 3; ++i) v(i) = p[i];
    return out;
}

DepthMap mapFromArray(py::handle depth, const Camera& camera, const DepthMapReading& reading, DepthQuantity quantity)
{
    const py::array a = numericArray(depth, "depth");
    if (a.ndim() != 2 || a.shape(0) != camera.height() || a.shape(1) != camera.width())
        fail("depth must have shape (" + std::to_string(camera.height()) + ", " + std::to_string(camera.width()) +
             ") = (camera.height, camera.width), got " + shapeText(a));
    const bool integer = a.dtype().kind() != 'f';
    if (integer && !(reading.scale > 0))
        fail("depth is an integer array (" + dtypeText(a) +
             "): give scale= (stored value = depth × scale, e.g. 1000 for millimetres; 0 = miss)");
    const DoubleArray d = asDoubles(a);
    DepthMapFile stored;
    stored.width = camera.width(), stored.height = camera.height();
    stored.value.assign(d.data(), d.data() + d.size());
    depthsFromStored(stored,
                     integer ? StoredValues::Integer : (a.dtype().itemsize() == 2 ? StoredValues::Half : StoredValues::Float),
                     reading);
    return DepthMap::of(std::move(stored), quantity, reading);
}

}  // namespace zcheck::python
