#include "shape.hpp"

#include <orogen/error.hpp>
#include <orogen/parallel.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

namespace orogen::shape {

Kind kind_from_name(std::string_view name) {
    if (name == "crooked") return Kind::crooked;
    if (name == "pyramid") return Kind::pyramid;
    if (name == "hemisphere") return Kind::hemisphere;
    if (name == "flat") return Kind::flat;
    if (name == "plane") return Kind::plane;
    if (name == "cone") return Kind::cone;
    throw BadInput("shape: unknown kind '" + std::string(name) +
                   "'; use one of crooked, pyramid, hemisphere, flat, plane, cone");
}

void make_shape(GridView t, const ShapeParams& p) {
    if (t.width < 1 || t.height < 1) throw BadInput("shape: the grid is empty");
    const double w = std::max(t.width - 1, 1), h = std::max(t.height - 1, 1);  // samples
    const double cx = 0.5 * (t.width - 1), cy = 0.5 * (t.height - 1);
    const double radius = 0.5 * std::min(w, h);  // samples
    const double rad = std::numbers::pi / 180.0;
    const double rise = std::tan(p.slope * rad) * t.cell;  // metres per sample along `direction`
    const double dx = std::cos(p.direction * rad), dy = std::sin(p.direction * rad);
    // Plane: the lowest corner along the direction sits at `height`.
    const double low = std::min({0.0, w * dx, h * dy, w * dx + h * dy});
    parallel_for(0, t.height, 16, [&](std::int64_t y0, std::int64_t y1) {
        for (std::int64_t yi = y0; yi < y1; ++yi) {
            float* row = t.row(int(yi));
            const double y = double(yi), v = y / h;
            for (int xi = 0; xi < t.width; ++xi) {
                const double x = xi, u = x / w;
                const double d = std::hypot(x - cx, y - cy) / radius;  // 1 at the rim
                double z = 0;
                switch (p.kind) {
                    case Kind::crooked:
                        // 60 % a tilt falling south, 40 % ridges that twist as they run south.
                        z = 0.6 * (1.0 - v) +
                            0.4 * (0.5 + 0.5 * std::sin(3.0 * std::numbers::pi * u + 2.0 * std::numbers::pi * v * v));
                        z *= p.height;
                        break;
                    case Kind::pyramid:
                        z = p.height * (1.0 - std::max(std::abs(2.0 * u - 1.0), std::abs(2.0 * v - 1.0)));
                        break;
                    case Kind::hemisphere: z = p.height * std::sqrt(std::max(0.0, 1.0 - d * d)); break;
                    case Kind::flat: z = p.height; break;
                    case Kind::plane: z = p.height + rise * (x * dx + y * dy - low); break;
                    case Kind::cone: z = p.height * std::max(0.0, 1.0 - d); break;
                }
                row[xi] = float(z);
            }
        }
    });
}

}  // namespace orogen::shape
