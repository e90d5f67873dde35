#pragma once
// How a depth map file is to be read — which channel, what scale and offset, which stored
// values mean "no surface" — decided here, in zcheck::depthmaps, so that command lines and the
// Python module can check the options without loading the image library (image_io.h reads).
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace zcheck {

// The stored values that mark "no surface" (renderers use 0, 65535, 1e10, NaN or +inf),
// compared with the value as the file stores it, before scale and offset. Written as a number
// ("0", "65535", "1e10", "nan", "inf") for equality, or as a comparison (">=1e9", ">1e9",
// "<=0", "<0").
struct MissRule {
    enum class Test : std::uint8_t { None, Equal, IsNan, Greater, GreaterEqual, Less, LessEqual };
    Test test = Test::None;
    double value = 0;

    // Throws Error naming the text and the accepted forms.
    static MissRule parse(const std::string& text);
    bool given() const { return test != Test::None; }
    bool matches(double stored) const;
    std::string text() const { return written_; }  // as given to parse ("" when not given)

private:
    std::string written_;
};

// A sensor's noise as its depth grows: standard deviation σ(z) = a + b·(z − z0)² in map units, z
// the map's own value at the pixel (eye-z, or range for a distance map). Written "kinect" (the
// Kinect v1 model of Nguyen et al. 2012 in metres: 0.0012 + 0.0019·(z − 0.4)²), "A+B*z^2" or
// "A+B*(z-C)^2". A map declaring it is allowed kSigmas·σ(z) at each pixel.
struct NoiseModel {
    static constexpr double kSigmas = 6;
    double a = 0, b = 0, z0 = 0;

    bool any() const { return a > 0 || b > 0; }
    double sigma(double z) const { return a + b * (z - z0) * (z - z0); }
    double allowance(double z) const { return any() ? kSigmas * sigma(z) : 0.0; }
    // Throws Error naming `name`, the text and the accepted forms.
    static NoiseModel parse(const std::string& text, const std::string& name = "--noise-model");
    // "0.0012+0.0019*(z-0.4)^2", "0.001+0.002*z^2": what parse reads back; "" for none.
    std::string text() const;
    bool operator==(const NoiseModel& o) const { return a == o.a && b == o.b && z0 == o.z0; }
};

// What a map's producer declares of its values, beyond how to read them: judged with, never
// applied to the values (a map is never "fixed"). Nothing declared: every value is exact to its
// storage (binary32, binary16, or an integer file's step) and every pixel where the surface is
// hit holds a value.
struct MapAccuracy {
    double quantum = 0;    // values rounded to multiples of this (map units, after scale); 0: none
    double relative = 0;   // values good to ± (absolute + relative·|value|) (map units) ...
    double absolute = 0;
    NoiseModel noise;         // ... and ± NoiseModel::kSigmas·σ(value) (map units)
    bool allowHoles = false;  // ... and a missing value where the surface is hit is a hole, not a failure

    bool any() const { return quantum > 0 || relative > 0 || absolute > 0 || noise.any() || allowHoles; }
    // Whether any number is declared (all but allowHoles): the accuracy verify judges as a whole
    // (a bias it may not absorb, a grid the values must lie on, at most a tenth of the depth).
    bool anyAccuracy() const { return quantum > 0 || relative > 0 || absolute > 0 || noise.any(); }
    // The rule each declared number keeps, whoever declares it: finite and ≥ 0, and below 1 for
    // the relative tolerance. Returns `value`, or throws Error "<name> must be a finite number
    // >= 0[ and below 1], got <value>", `name` as the caller calls it ("rel_tolerance").
    static double requireDeclared(double value, const std::string& name, bool relative);
    // Throws Error naming `where` and the field unless every number keeps requireDeclared's rule.
    void require(const std::string& where) const;
    // The options that declare this ("--quantum 0.001 --allow-holes"), "" for none.
    std::string options() const;
    // The fields declared here (non-zero, true), the others from `fallback`.
    MapAccuracy over(const MapAccuracy& fallback) const;
    bool operator==(const MapAccuracy& o) const
    {
        return quantum == o.quantum && relative == o.relative && absolute == o.absolute && noise == o.noise &&
               allowHoles == o.allowHoles;
    }
};

// How to read a depth map. The depth of a stored value v is v / scale + offset (scale 1 and
// offset 0 when not given); integer files need a scale.
struct DepthMapReading {
    std::string channel;          // the channel to read; "" chooses one (chooseDepthChannel)
    std::string quantityChannel;  // zcheck's own name for the declared quantity's channel
                                  // (export.h), preferred when several channels name depth
    double scale = 0;             // 0: not given
    std::optional<double> offset; // none: not given (0); a given 0 still wins over a sidecar's
    MissRule miss;                // not given: integer files' 0 is a miss; NaN always is
    MapAccuracy accuracy;         // what the producer declares (judged with, not applied)

    // The depth of a value as the file stores it: NaN for a miss, else stored / scale + offset.
    double depthOf(double stored, bool integerFile) const
    {
        if (std::isnan(stored) || (miss.given() ? miss.matches(stored) : integerFile && stored == 0)) return NAN;
        return (scale > 0 ? stored / scale : stored) + offset.value_or(0.0);
    }
    // A step between stored values as a step between depths.
    double depthStepOf(double storedStep) const { return scale > 0 ? storedStep / scale : storedStep; }

    // The rules of a given scale and offset, whoever gives them (options, keyword arguments): a
    // scale is positive and finite (0 in `scale` means none was given), an offset finite. Each
    // throws Error "<name> must be a positive finite number, got -2" (resp. "a finite number"),
    // `name` as the caller calls the value ("--scale", "scale").
    static void requireScale(double scale, const std::string& name);
    static void requireOffset(double offset, const std::string& name);
    // A file that stores integers needs a scale: throws Error "depth map '<path>' stores integers
    // (<storage>): give --scale (...)" when none was given. Every integer format's reader asks this.
    void requireScaleForIntegers(const std::string& path, const std::string& storage) const;
};

// The channel of a file with channels `names` that holds depth: `wanted` when given (Error
// listing the channels when there is none of that name); the only channel; `quantityChannel`
// when present; else the one channel named as depth — Z, depth, a layer's *.Z or *.depth
// (Blender's ViewLayer.Depth.Z), or zcheck's window, ndc, distance. Several such channels, or
// none, is an Error that lists them and asks for --channel.
std::string chooseDepthChannel(const std::string& path, const std::vector<std::string>& names, const std::string& wanted,
                               const std::string& quantityChannel);

// A depth map read from a file, row 0 at the top as seen (PFM's bottom-to-top rows are flipped).
struct DepthMapFile {
    int width = 0, height = 0;
    std::string channel;          // the channel read
    std::vector<double> value;    // width·height; NaN where the file marks a miss
    double valueQuantum = 0;      // the storage step of `value`: 1/scale for integer files, 0 for
                                  // float files (binary32: the step depends on the value)
    std::vector<float> valueStep; // binary16 files (EXR HALF, .npy float16): each value's own step
                                  // (its binary16 spacing, after scale); empty otherwise
};

// How a map's values were stored, which decides the step between neighbouring values.
enum class StoredValues {
    Float,    // binary32 or binary64: the step depends on the value (DepthMap: binary32's spacing)
    Half,     // binary16 (EXR HALF, .npy float16, a NumPy float16 array): each value's own step
    Integer,  // integer codes (16-bit PNG, integer TIFF, .npy, HDF5): a step of 1, 1/scale in depth
};
// Turns `map.value`, holding the values as they were stored (row 0 at the top), into depths the
// reading's way (DepthMapReading::depthOf: NaN for a miss, else stored / scale + offset), and
// records the step they were stored with: valueQuantum 1/scale for integers (the caller has
// refused integers without a scale), valueStep each half float's spacing after scale
// (binary16Step), nothing for Float. The one rule every reader of stored values and the
// Python module's arrays use.
void depthsFromStored(DepthMapFile& map, StoredValues stored, const DepthMapReading& reading);

// The size a file declares against the camera's (0 × 0: any size a camera may have: 1..16384
// per side, 2^25 pixels in all); throws Error naming the file and both sizes.
void requireDepthMapSize(const std::string& path, long long width, long long height, int expectedWidth, int expectedHeight);

// Throws Error "cannot read depth map '<path>': <why>".
[[noreturn]] void refuseDepthMap(const std::string& path, const std::string& why);

// The spacing of binary16 values around `stored` (the step of its exponent's range; a
// subnormal's for the smallest): what a half-float map's value may have been rounded by.
double binary16Step(double stored);

// The reading with the fields not given (an empty channel, scale 0, no offset, no miss rule,
// nothing declared) taken from a sidecar: a JSON object whose "channel", "miss" (a number, or a
// rule such as ">=1e9", "nan", "inf"), "scale", "offset", "quantum", "rel_tolerance",
// "abs_tolerance" and "allow_holes" keys describe the map; other keys are ignored and null is
// absent. Throws Error naming the sidecar and the key that breaks its rule.
DepthMapReading withSidecar(DepthMapReading reading, const std::string& sidecar);

// What a sidecar says the map is, beyond how to read it. zcheck's export writes the camera that
// rendered the map ("camera", with "zcheck_version") and each channel's quantity ("channels":
// [{"name": "Z", "quantity": "eye-z"}, ...]); other producers' sidecars may have neither.
struct SidecarSubject {
    bool hasCamera = false;  // readCameraFile(sidecar) reads it
    std::vector<std::pair<std::string, std::string>> channelQuantities;  // {channel, quantity}, depth quantities only
    // The quantity of `channel` ("" : the sidecar's only depth channel); nothing when the sidecar
    // does not say. Throws Error naming the sidecar when several channels leave it open.
    std::optional<std::string> quantityOf(const std::string& sidecar, const std::string& channel) const;
};
SidecarSubject sidecarSubject(const std::string& sidecar);

}  // namespace zcheck
