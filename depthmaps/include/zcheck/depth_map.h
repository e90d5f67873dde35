#pragma once
// A depth map rendered elsewhere, as zcheck judges it (library zcheck::diagnose): values per
// pixel in one depth quantity (window, ndc, eye-z or distance), row 0 at the top, with the step
// each value was stored with and the accuracy its producer declares.
//
//   zcheck::DepthMapFile file = ...;   // as read with `reading` (depth_map_reading.h, image_io.h)
//   const zcheck::DepthMap map = zcheck::DepthMap::of(std::move(file), zcheck::DepthQuantity::EyeZ, reading);
//   const zcheck::VerifyResult run = verifier.verify(camera, map);   // map_verifier.h
//
// Misses and values a quantity cannot hold are kindOfDepthValue's (inverse_projection.h).
#include "zcheck/depth_map_reading.h"
#include "zcheck/quantity.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

namespace zcheck {

// How one value of a map is judged (value units): the step it was stored with (0: binary32's own
// spacing at the value), and the accuracy its producer declares, ± declaredAt(value): the grid
// it was rounded to (its step: half for the rounding, half for the computation before it, as a
// unorm16 depth buffer's one quantum), absolute + relative·|value|, and the noise model's 6σ.
struct ValueAccuracy {
    double step = 0;
    double grid = 0;
    double relative = 0, absolute = 0;
    NoiseModel noise;
    double declaredAt(double value) const
    {
        return grid + absolute + relative * std::abs(value) + noise.allowance(std::abs(value));
    }
};

// A depth map rendered elsewhere, as read: values per pixel in one depth quantity.
struct DepthMap {
    int width = 0, height = 0;
    DepthQuantity quantity = DepthQuantity::Window;
    std::vector<double> value;   // row 0 at the top; misses and values out of range as
                                 // kindOfDepthValue (inverse_projection.h) defines them
    double valueQuantum = 0;     // the storage step of `value` (1/scale for integer files); 0: binary32
    std::vector<float> valueStep;  // each value's own step (binary16 files), overriding valueQuantum; or empty
    MapAccuracy accuracy;        // what its producer declares (depth_map_reading.h)
    double scale = 0, offset = 0;  // how stored values became `value`: stored / scale + offset (scale 0: 1)

    // A map of `quantity` as a file was read `reading`'s way, with what the reading declares.
    static DepthMap of(DepthMapFile file, DepthQuantity quantity, const DepthMapReading& reading)
    {
        return {file.width,           file.height,      quantity,      std::move(file.value), file.valueQuantum,
                std::move(file.valueStep), reading.accuracy, reading.scale, reading.offset.value_or(0.0)};
    }
    // A map of values exact to their binary32 spacing, nothing declared (tests, arrays).
    static DepthMap exact(int width, int height, DepthQuantity quantity, std::vector<double> values)
    {
        DepthMap map;
        map.width = width, map.height = height, map.quantity = quantity, map.value = std::move(values);
        return map;
    }
    // A value as the file stored it (before scale and offset).
    double storedOf(double v) const { return (v - offset) * (scale > 0 ? scale : 1.0); }
    // Value i's: its storage step (its own or the file's) and the declared accuracy.
    ValueAccuracy accuracyAt(std::size_t i) const
    {
        return {valueStep.empty() ? valueQuantum : double(valueStep[i]), accuracy.quantum, accuracy.relative,
                accuracy.absolute, accuracy.noise};
    }
    // Whether the values were stored as integers (a 16-bit PNG or TIFF: valueQuantum is 1/scale).
    bool integerStorage() const { return valueQuantum > 0 && valueStep.empty(); }
};

}  // namespace zcheck
