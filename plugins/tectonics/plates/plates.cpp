// plates.cpp — the plate simulation: Box2D world, beams, contact listener,
// boundary relief, rifting, history.
#include "plates.hpp"

#include "profiles.hpp"

#include <orogen/error.hpp>
#include <orogen/parallel.hpp>
#include <orogen/random.hpp>
#include <orogen/relief/range.hpp>  // orogen::relief::raise_range (libs/relief)

#include <box2d/box2d.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <memory>
#include <numbers>
#include <string>

namespace orogen::plates {

namespace {

// What each random number is for: the first counter after the seed.
enum Purpose : std::uint64_t {
    purpose_cut_x = 1,
    purpose_cut_y,
    purpose_cut_angle,
    purpose_oceanic,
    purpose_density,
    purpose_velocity_angle,
    purpose_velocity_size,
    purpose_spin,
    purpose_range,
    purpose_relief,
};

constexpr double min_gap_units = 0.05;  // u: 10 × b2_linearSlop, so Box2D never welds a vertex away

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

Point2 operator+(Point2 a, Point2 b) { return {a.x + b.x, a.y + b.y}; }
Point2 operator-(Point2 a, Point2 b) { return {a.x - b.x, a.y - b.y}; }
Point2 operator*(double s, Point2 a) { return {s * a.x, s * a.y}; }
double dot(Point2 a, Point2 b) { return a.x * b.x + a.y * b.y; }
Point2 to_point(b2Vec2 v) { return {double(v.x), double(v.y)}; }
b2Vec2 to_b2(Point2 p) { return b2Vec2(float(p.x), float(p.y)); }

// A triangle wave in [0, 1]: 0 at phase 0, 1 at phase 0.5.
double triangle(double phase) {
    const double f = phase - std::floor(phase);
    return 1.0 - std::abs(2.0 * f - 1.0);
}

// Clip segment a–b to [0, w] × [0, h] (Liang–Barsky). False if it lies outside.
bool clip_segment(Point2& a, Point2& b, double w, double h) {
    double t0 = 0.0, t1 = 1.0;
    const double dx = b.x - a.x, dy = b.y - a.y;
    const double p[4] = {-dx, dx, -dy, dy};
    const double q[4] = {a.x, w - a.x, a.y, h - a.y};
    for (int i = 0; i < 4; ++i) {
        if (p[i] == 0.0) {
            if (q[i] < 0.0) return false;
        } else {
            const double r = q[i] / p[i];
            if (p[i] < 0.0) t0 = std::max(t0, r);
            else t1 = std::min(t1, r);
        }
    }
    if (t0 > t1) return false;
    const Point2 a0 = a;
    a = {a0.x + t0 * dx, a0.y + t0 * dy};
    b = {a0.x + t1 * dx, a0.y + t1 * dy};
    return true;
}

struct PlateBody {
    b2Body* body = nullptr;
    int id = 0;
    double density = 1.0;
    double impulse = 0.0;  // accumulated plate–plate normal impulse since the last rift attempt
    double stress_x = 0.0, stress_y = 0.0;  // impulse-weighted sum of contact points, plate frame (u·N·s)
};

struct Beam {
    b2Body* body = nullptr;
    Point2 rest;  // centre at rest, u
    Point2 inward;  // unit normal into the area
    double push = 0.0;  // inward offset amplitude as a multiple of the stroke (negative: outward)
    double phase = 0.0;  // of the triangle wave, in periods
    Point2 convey;  // surface velocity (conveyor belt) of the beam's face, u/s
};

struct PendingEvent {
    b2Contact* contact = nullptr;
    PlateBody* a = nullptr;
    PlateBody* b = nullptr;
    Point2 p0, p1;  // u
    Point2 normal;  // from a to b
    BoundaryKind kind = BoundaryKind::convergent;
    double impulse = 0.0;
};

Polygon world_polygon(const b2Body* body) {
    const b2Fixture* fixture = body->GetFixtureList();
    const auto* shape = static_cast<const b2PolygonShape*>(fixture->GetShape());
    Polygon poly;
    poly.reserve(std::size_t(shape->m_count));
    for (int i = 0; i < shape->m_count; ++i) poly.push_back(to_point(body->GetWorldPoint(shape->m_vertices[i])));
    return poly;
}

/// Every relief width scales with the Voronoi cell size (profiles.hpp).
ReliefShape relief_shape(const Params& params, int w, int h) {
    ReliefShape shape;
    shape.cell = std::sqrt(double(w) * double(h) / double(std::max(1, params.cones)));
    shape.range_height = params.height;
    shape.jitter = params.jitter;
    shape.trench_depth = params.trench_depth;
    shape.arc_height = params.arc_height;
    shape.rift_depth = params.rift_depth;
    shape.ridge_height = params.ridge_height;
    shape.saturation = params.saturation;
    return shape;
}

/// One stamp: into the relief's activity fields, or (cells) straight onto the terrain that holds `at` of the
/// relief's grid (the whole grid in one process, a tile in a tiled run).
void draw_stamp(const ReliefStamp& stamp, const Params& params, BoundaryRelief& relief, GridView terrain,
                GridView* uplift, TileRect at) {
    switch (stamp.kind) {
        case ReliefStamp::Kind::range: relief.add_range(stamp.a, stamp.b); break;
        case ReliefStamp::Kind::subduction: relief.add_subduction(stamp.a, stamp.b, stamp.toward_light); break;
        case ReliefStamp::Kind::rift: relief.add_rift(stamp.a, stamp.b); break;
        case ReliefStamp::Kind::cells: {
            const orogen::relief::RangeParams range{params.cones, params.height, params.jitter};
            orogen::relief::raise_range(terrain,
                                        orogen::relief::GridWindow{relief.width(), relief.height(), at.x0, at.y0},
                                        stamp.a, stamp.b, range, stamp.seed, uplift);
            break;
        }
    }
}

/// The plate and boundary layers of the rectangle `at` of the replay's grid (the whole grid in one process,
/// a tile in a tiled run): the final plates' ids, then every event's segment, kind as the value.
void draw_layers(const Replay& replay, const Layers& layers, TileRect at) {
    if (layers.plate.data) {
        std::fill(layers.plate.data, layers.plate.data + layers.plate.size(), -1.0f);
        for (std::size_t i = 0; i < replay.final_polygons.size(); ++i)
            fill_polygon(layers.plate, at, replay.final_polygons[i], float(replay.final_ids[i]));
    }
    if (layers.boundary.data) {
        const int radius = std::max(0, std::min(replay.width, replay.height) / 512);
        for (const CollisionEvent& e : replay.boundaries)
            draw_segment(layers.boundary, at, (1.0 / replay.cell) * e.a, (1.0 / replay.cell) * e.b, float(int(e.kind)),
                         radius);
    }
}

class Simulation : public b2ContactListener {
public:
    Simulation(const Params& params, std::uint64_t seed, const Layers& layers)
        : params_(params), seed_(seed), layers_(layers), world_(b2Vec2(0.0f, 0.0f)) {
        const int w = layers.terrain.width, h = layers.terrain.height;
        size_ = area_size(w, h);
        spu_ = samples_per_unit(w, h);
        cell_ = layers.terrain.cell;
        draws_ = layers.terrain.data != nullptr;  // else simulate_events(): the replay only
        if (draws_) relief_.emplace(w, h, relief_shape(params, w, h), random::hash(seed, purpose_relief));
        result_.replay.width = w;
        result_.replay.height = h;
        result_.replay.cell = cell_;
        world_.SetAllowSleeping(false);  // a resting plate must still feel the beams
        world_.SetContactListener(this);
        result_.history.width = (w - 1) * cell_;
        result_.history.height = (h - 1) * cell_;
    }

    void add_plate(const PlateSpec& spec, int id) { plates_.push_back(create_plate(spec, id)); }

    // Rifting never makes a plate smaller than half the mean start plate, so
    // splits cannot cascade into slivers (small plates are light and take
    // impulse as readily as big ones).
    void set_min_rift_part(double area) { min_rift_part_ = area; }

    void add_beams() {
        const double thick = 4.0;  // u: thick enough that no plate tunnels through
        const double m = margin_units;
        const double reach = m + thick + params_.stroke + 1.0;  // beams overlap past the corners
        const double sx = size_.x, sy = size_.y;
        struct Def {
            Point2 centre, inward;
            double hx, hy;
        };
        const Def defs[4] = {
            {{-m - 0.5 * thick, 0.5 * sy}, {1, 0}, 0.5 * thick, 0.5 * sy + reach},  // west
            {{sx + m + 0.5 * thick, 0.5 * sy}, {-1, 0}, 0.5 * thick, 0.5 * sy + reach},  // east
            {{0.5 * sx, -m - 0.5 * thick}, {0, 1}, 0.5 * sx + reach, 0.5 * thick},  // north (y south)
            {{0.5 * sx, sy + m + 0.5 * thick}, {0, -1}, 0.5 * sx + reach, 0.5 * thick},  // south
        };
        const double s = params_.speed;
        for (int i = 0; i < 4; ++i) {
            Beam beam;
            beam.rest = defs[i].centre;
            beam.inward = defs[i].inward;
            switch (params_.drive) {
                case Drive::still: break;
                case Drive::converge:  // west+east squeeze together, north+south half a period later
                    beam.push = 1.0;
                    beam.phase = i < 2 ? 0.0 : 0.5;
                    break;
                case Drive::thesis:  // every beam moves the same way at once: the box translates and shakes
                    beam.push = (i % 2 == 0) ? 1.0 : -1.0;
                    beam.phase = 0.0;
                    break;
                case Drive::rotate: {  // faces convey clockwise on the map (x east, y south) and squeeze gently
                    const Point2 conveys[4] = {{0, -s}, {0, s}, {s, 0}, {-s, 0}};
                    beam.convey = conveys[i];
                    beam.push = 0.5;
                    beam.phase = i < 2 ? 0.0 : 0.5;
                    break;
                }
                case Drive::shear:  // north face conveys east, south face west; both squeeze a little
                    if (i == 2) beam.convey = {s, 0};
                    if (i == 3) beam.convey = {-s, 0};
                    beam.push = i >= 2 ? 0.5 : 0.0;
                    break;
            }
            b2BodyDef def;
            def.type = b2_kinematicBody;
            def.position = to_b2(beam.rest);
            beam.body = world_.CreateBody(&def);
            b2PolygonShape box;
            box.SetAsBox(float(defs[i].hx), float(defs[i].hy));
            b2FixtureDef fixture;
            fixture.shape = &box;
            fixture.friction = float(params_.friction);
            fixture.restitution = float(params_.restitution);
            beam.body->CreateFixture(&fixture);
            beams_[i] = beam;
        }
    }

    Result run(const std::function<void(std::int64_t)>& on_step, std::int64_t snapshot_every = 0,
               const SnapshotFn& on_snapshot = {}) {
        snapshot(0);
        for (std::int64_t step = 1; step <= params_.steps; ++step) {
            step_ = step;
            drive_beams(step);
            const auto t0 = Clock::now();
            world_.Step(float(params_.dt), params_.velocity_iterations, params_.position_iterations);
            result_.stats.box2d_seconds += seconds_since(t0);
            check_finite(step);
            const auto t1 = Clock::now();
            apply_events(step);
            result_.stats.relief_seconds += seconds_since(t1);
            if (params_.rift_threshold > 0.0) rift(step);
            if (step % std::max(1, params_.record_every) == 0 || step == params_.steps) snapshot(step);
            if (draws_ && on_snapshot && snapshot_every > 0 && step % snapshot_every == 0 && step < params_.steps) {
                const GridView& t = layers_.terrain;
                scratch_.assign(t.data, t.data + t.size());
                GridView copy{scratch_.data(), t.width, t.height, t.cell};
                relief_->apply(copy);
                on_snapshot(step, copy);
            }
            if (on_step) on_step(step);
        }
        const auto t2 = Clock::now();
        if (draws_) relief_->apply(layers_.terrain, uplift());  // the accumulated boundaries, saturated and textured
        result_.stats.relief_seconds += seconds_since(t2);
        finish();
        return std::move(result_);
    }

    // ------------------------------------------------------- contact listener

    void PreSolve(b2Contact* contact, const b2Manifold*) override {
        b2Body* body_a = contact->GetFixtureA()->GetBody();
        b2Body* body_b = contact->GetFixtureB()->GetBody();
        const bool dyn_a = body_a->GetType() == b2_dynamicBody, dyn_b = body_b->GetType() == b2_dynamicBody;
        if (!dyn_a || !dyn_b) {
            convey(contact, dyn_a ? body_b : body_a, !dyn_a);
            return;
        }
        // Only two-point contacts between plates count (thesis 3.6.1): an edge
        // against an edge, which gives a segment to raise a range along.
        if (contact->GetManifold()->pointCount != 2) return;
        auto* pa = reinterpret_cast<PlateBody*>(body_a->GetUserData().pointer);
        auto* pb = reinterpret_cast<PlateBody*>(body_b->GetUserData().pointer);
        const std::uint64_t key =
            (std::uint64_t(std::uint32_t(std::min(pa->id, pb->id))) << 32) | std::uint32_t(std::max(pa->id, pb->id));
        const auto [it, first_touch] = last_touch_.try_emplace(key, step_);
        const bool begins = first_touch || (it->second != step_ - 1 && it->second != step_);
        it->second = step_;
        if (!begins) return;  // the thesis raised one range per contact begin, not per step
        b2WorldManifold wm;
        contact->GetWorldManifold(&wm);
        const Point2 p0 = to_point(wm.points[0]), p1 = to_point(wm.points[1]);
        const Point2 normal = to_point(wm.normal);
        const b2Vec2 mid(0.5f * (wm.points[0].x + wm.points[1].x), 0.5f * (wm.points[0].y + wm.points[1].y));
        const Point2 rel = to_point(body_b->GetLinearVelocityFromWorldPoint(mid)) -
            to_point(body_a->GetLinearVelocityFromWorldPoint(mid));
        const double speed = std::hypot(rel.x, rel.y);
        if (!(speed >= params_.min_speed)) {
            ++result_.stats.events[0];
            return;
        }
        // Approaching along the normal (from a to b, so b moving toward a
        // gives a negative component) within 60° → convergent; separating
        // within 60° → divergent; otherwise mostly tangential → transform.
        const double c = dot(rel, normal) / speed;
        const BoundaryKind kind =
            c < -0.5 ? BoundaryKind::convergent : (c > 0.5 ? BoundaryKind::divergent : BoundaryKind::transform);
        pending_.push_back({contact, pa, pb, p0, p1, normal, kind, 0.0});
    }

    void PostSolve(b2Contact* contact, const b2ContactImpulse* impulse) override {
        b2Body* body_a = contact->GetFixtureA()->GetBody();
        b2Body* body_b = contact->GetFixtureB()->GetBody();
        if (body_a->GetType() != b2_dynamicBody || body_b->GetType() != b2_dynamicBody) return;
        auto* pa = reinterpret_cast<PlateBody*>(body_a->GetUserData().pointer);
        auto* pb = reinterpret_cast<PlateBody*>(body_b->GetUserData().pointer);
        b2WorldManifold wm;
        contact->GetWorldManifold(&wm);
        double total = 0.0;
        for (int i = 0; i < impulse->count; ++i) {
            const double j = std::max(0.0f, impulse->normalImpulses[i]);
            total += j;
            for (PlateBody* p : {pa, pb}) {
                // In the plate's own frame: the plate moves and turns between
                // the contacts that load it.
                const b2Vec2 local = p->body->GetLocalPoint(wm.points[i]);
                p->stress_x += j * double(local.x);
                p->stress_y += j * double(local.y);
            }
        }
        pa->impulse += total;
        pb->impulse += total;
        for (PendingEvent& e : pending_)
            if (e.contact == contact) e.impulse += total;
    }

private:
    PlateBody* create_plate(const PlateSpec& spec, int id) {
        const Point2 c = centroid(spec.polygon);
        b2Vec2 local[b2_maxPolygonVertices];
        const int n = int(spec.polygon.size());
        for (int i = 0; i < n; ++i) local[i] = to_b2(spec.polygon[std::size_t(i)] - c);
        b2BodyDef def;
        def.type = b2_dynamicBody;
        def.position = to_b2(c);
        auto holder = std::make_unique<PlateBody>();
        holder->id = id;
        holder->density = spec.density;
        def.userData.pointer = reinterpret_cast<std::uintptr_t>(holder.get());
        holder->body = world_.CreateBody(&def);
        b2PolygonShape shape;
        shape.Set(local, n);
        b2FixtureDef fixture;
        fixture.shape = &shape;
        fixture.density = float(spec.density);
        fixture.friction = float(params_.friction);
        fixture.restitution = float(params_.restitution);
        holder->body->CreateFixture(&fixture);
        // Set after creation: b2BodyDef asserts finite velocities, and a
        // velocity that is not finite must surface as a failed step instead.
        holder->body->SetLinearVelocity(to_b2(spec.velocity));
        holder->body->SetAngularVelocity(float(spec.angular_velocity));
        owned_.push_back(std::move(holder));
        return owned_.back().get();
    }

    // A beam touching a plate: give its face the beam's conveyor velocity
    // (Box2D's tangent speed), so friction drags the plate along.
    void convey(b2Contact* contact, const b2Body* beam_body, bool beam_is_a) {
        for (const Beam& beam : beams_) {
            if (beam.body != beam_body) continue;
            if (beam.convey.x == 0.0 && beam.convey.y == 0.0) return;
            b2WorldManifold wm;
            contact->GetWorldManifold(&wm);
            const Point2 tangent{double(wm.normal.y), -double(wm.normal.x)};  // b2Cross(normal, 1)
            // The solver drives (v_b − v_a)·tangent to the tangent speed.
            const double along = dot(beam.convey, tangent);
            contact->SetTangentSpeed(float(beam_is_a ? along : -along));
            return;
        }
    }

    // Beams follow a triangle wave of period 2·stroke/speed: each moves at
    // `speed` between rest and `stroke` inward. Their velocity is set so they
    // land exactly on the wave at the end of the step.
    void drive_beams(std::int64_t step) {
        if (params_.drive == Drive::still) return;
        const double period = 2.0 * params_.stroke / std::max(params_.speed, 1e-12);
        const double t = double(step) * params_.dt;
        for (Beam& beam : beams_) {
            const double offset = beam.push * params_.stroke * triangle(t / period + beam.phase);
            const Point2 target = beam.rest + offset * beam.inward;
            const Point2 now = to_point(beam.body->GetPosition());
            beam.body->SetLinearVelocity(to_b2((1.0 / params_.dt) * (target - now)));
        }
    }

    void check_finite(std::int64_t step) const {
        for (const PlateBody* p : plates_) {
            const b2Vec2 pos = p->body->GetPosition();
            const b2Vec2 vel = p->body->GetLinearVelocity();
            if (!std::isfinite(pos.x) || !std::isfinite(pos.y) || !std::isfinite(p->body->GetAngle()) ||
                !std::isfinite(vel.x) || !std::isfinite(vel.y))
                throw Error("plate " + std::to_string(p->id) + " has a non-finite position at step " +
                            std::to_string(step) + " (Box2D diverged; lower dt or speed)");
        }
    }

    GridView* uplift() { return layers_.uplift.data ? &layers_.uplift : nullptr; }

    void apply_events(std::int64_t step) {
        const double w = layers_.terrain.width - 1, h = layers_.terrain.height - 1;
        for (const PendingEvent& e : pending_) {
            ++result_.stats.events[int(e.kind)];
            CollisionEvent rec;
            rec.step = step;
            rec.plate_a = e.a->id;
            rec.plate_b = e.b->id;
            rec.a = (spu_ * cell_) * e.p0;
            rec.b = (spu_ * cell_) * e.p1;
            rec.kind = e.kind;
            rec.impulse = e.impulse;
            result_.history.collisions.push_back(rec);
            const std::uint64_t index = result_.history.collisions.size() - 1;

            Point2 a = spu_ * e.p0, b = spu_ * e.p1;  // samples
            if (e.kind == BoundaryKind::transform || !clip_segment(a, b, w, h)) continue;
            ReliefStamp stamp;
            stamp.step = step;
            stamp.a = a;
            stamp.b = b;
            const double contrast = e.a->density - e.b->density;
            if (e.kind == BoundaryKind::divergent) {
                stamp.kind = ReliefStamp::Kind::rift;
            } else if (std::abs(contrast) >= params_.subduction_contrast) {
                // The denser plate dives: the overriding (light) plate lies on
                // the normal's side if a is the dense one.
                stamp.kind = ReliefStamp::Kind::subduction;
                stamp.toward_light = contrast > 0.0 ? e.normal : -1.0 * e.normal;
                ++result_.stats.subductions;
            } else if (params_.ranges == RangeStyle::peaks) {
                stamp.kind = ReliefStamp::Kind::range;
            } else {
                stamp.kind = ReliefStamp::Kind::cells;
                stamp.seed = random::hash(seed_, purpose_range, index);
            }
            if (draws_)
                draw_stamp(stamp, params_, *relief_, layers_.terrain, uplift(),
                           TileRect{0, 0, layers_.terrain.width, layers_.terrain.height});
            result_.replay.stamps.push_back(stamp);
        }
        pending_.clear();
    }

    // Split the first plate whose accumulated impulse passed the threshold
    // along a line through its stress point and its centroid (so the parts
    // are comparable), turning the line up to ±36° if a part would be too
    // small or have more than 8 vertices. One rift per step.
    void rift(std::int64_t step) {
        if (int(plates_.size()) >= params_.max_plates) return;
        for (std::size_t i = 0; i < plates_.size(); ++i) {
            PlateBody& p = *plates_[i];
            if (p.impulse < params_.rift_threshold) continue;
            const Point2 stress =
                to_point(p.body->GetWorldPoint(b2Vec2(float(p.stress_x / p.impulse), float(p.stress_y / p.impulse))));
            p.impulse = p.stress_x = p.stress_y = 0.0;
            const Polygon poly = world_polygon(p.body);
            const double area = signed_area(poly);
            const Point2 c = centroid(poly);
            Point2 d = c - stress;
            if (std::hypot(d.x, d.y) < 1e-3) d = {1.0, 0.0};
            for (int k : {0, 1, -1, 2, -2, 3, -3}) {
                const double turn = k * std::numbers::pi / 15.0;
                const Point2 dk{d.x * std::cos(turn) - d.y * std::sin(turn),
                                d.x * std::sin(turn) + d.y * std::cos(turn)};
                auto parts = split_convex(poly, stress, dk, min_gap_units);
                if (!parts) continue;
                auto& [left, right] = *parts;
                const double al = signed_area(left), ar = signed_area(right);
                if (left.size() > max_plate_vertices || right.size() > max_plate_vertices) continue;
                if (std::min(al, ar) < std::max(0.2 * area, min_rift_part_)) continue;
                split_body(i, left, right, dk, al >= ar);
                ++result_.stats.rifts;
                (void)step;
                return;
            }
        }
    }

    void split_body(std::size_t index, const Polygon& left, const Polygon& right, Point2 d, bool left_keeps_id) {
        const PlateBody old = *plates_[index];
        const double len = std::hypot(d.x, d.y);
        const Point2 n{-d.y / len, d.x / len};  // toward the left part
        auto spec_of = [&](const Polygon& poly, double sign) {
            PlateSpec s;
            s.polygon = poly;
            const Point2 c = centroid(poly);
            s.velocity =
                to_point(old.body->GetLinearVelocityFromWorldPoint(to_b2(c))) + (sign * params_.rift_speed) * n;
            s.angular_velocity = old.body->GetAngularVelocity();
            s.density = old.density;
            return s;
        };
        const PlateSpec sl = spec_of(left, 1.0), sr = spec_of(right, -1.0);
        world_.DestroyBody(old.body);
        const int new_id = next_id_++;
        plates_[index] = create_plate(left_keeps_id ? sl : sr, old.id);
        plates_.push_back(create_plate(left_keeps_id ? sr : sl, new_id));
    }

    void snapshot(std::int64_t step) {
        PlateSnapshot snap;
        snap.step = step;
        snap.time = double(step) * params_.dt;
        const double scale = spu_ * cell_;
        for (const PlateBody* p : plates_) {
            PlateState s;
            s.id = p->id;
            for (const Point2& v : world_polygon(p->body)) s.polygon.push_back(scale * v);
            s.velocity = scale * to_point(p->body->GetLinearVelocity());
            s.density = p->density;
            snap.plates.push_back(std::move(s));
        }
        result_.history.snapshots.push_back(std::move(snap));
    }

    void finish() {
        std::vector<Polygon> in_samples;
        for (const PlateBody* p : plates_) {
            PlateSpec s;
            s.polygon = world_polygon(p->body);
            s.velocity = to_point(p->body->GetLinearVelocity());
            s.angular_velocity = p->body->GetAngularVelocity();
            s.density = p->density;
            Polygon samples;
            for (const Point2& v : s.polygon) samples.push_back(spu_ * v);
            in_samples.push_back(std::move(samples));
            result_.final_plates.push_back(std::move(s));
            result_.final_ids.push_back(p->id);
        }
        result_.replay.final_polygons = std::move(in_samples);
        result_.replay.final_ids = result_.final_ids;
        result_.replay.boundaries = result_.history.collisions;
        draw_layers(result_.replay, layers_, TileRect{0, 0, layers_.terrain.width, layers_.terrain.height});
    }

public:
    int next_id_ = 0;

private:
    const Params& params_;
    std::uint64_t seed_;
    Layers layers_;
    b2World world_;
    Point2 size_;
    double spu_ = 1.0, cell_ = 1.0, min_rift_part_ = 0.0;
    std::vector<std::unique_ptr<PlateBody>> owned_;  // stable addresses for Box2D user data
    std::vector<PlateBody*> plates_;  // alive plates, in creation order
    std::array<Beam, 4> beams_{};
    std::map<std::uint64_t, std::int64_t> last_touch_;  // plate pair → last step with a two-point contact
    std::vector<PendingEvent> pending_;
    std::int64_t step_ = 0;
    bool draws_ = true;  // false: simulate_events(), nothing drawn
    std::optional<BoundaryRelief> relief_;
    std::vector<float> scratch_;  ///< a time-lapse snapshot: the terrain with the relief so far
    Result result_;
};

}  // namespace

std::optional<Drive> parse_drive(std::string_view name) {
    for (std::size_t i = 0; i < drive_names.size(); ++i)
        if (drive_names[i] == name) return Drive(i);
    return std::nullopt;
}

std::optional<RangeStyle> parse_range_style(std::string_view name) {
    for (std::size_t i = 0; i < range_style_names.size(); ++i)
        if (range_style_names[i] == name) return RangeStyle(i);
    return std::nullopt;
}

Point2 area_size(int width, int height) {
    const int longer = std::max(width, height) - 1;
    if (longer <= 0) return {area_units, area_units};
    return {area_units * (width - 1) / longer, area_units * (height - 1) / longer};
}

double samples_per_unit(int width, int height) { return (std::max(width, height) - 1) / area_units; }

int max_plates(int width, int height) {
    const std::int64_t cells = std::int64_t(std::max(0, width - 1)) * std::int64_t(std::max(0, height - 1));
    return int(std::min<std::int64_t>(256, cells / 256));
}

std::vector<PlateSpec> random_plates(Point2 size, int count, double oceanic_fraction, double speed,
                                     std::uint64_t seed) {
    std::vector<Polygon> polys = {{{0.0, 0.0}, {size.x, 0.0}, {size.x, size.y}, {0.0, size.y}}};
    for (std::uint64_t cut = 0; int(polys.size()) < count; ++cut) {
        std::size_t largest = 0;
        for (std::size_t i = 1; i < polys.size(); ++i)
            if (signed_area(polys[i]) > signed_area(polys[largest])) largest = i;
        const Polygon poly = polys[largest];
        const double area = signed_area(poly);
        double x0 = poly[0].x, x1 = x0, y0 = poly[0].y, y1 = y0;
        for (const Point2& v : poly) {
            x0 = std::min(x0, v.x), x1 = std::max(x1, v.x), y0 = std::min(y0, v.y), y1 = std::max(y1, v.y);
        }
        bool done = false;
        for (std::uint64_t attempt = 0; attempt < 1000 && !done; ++attempt) {
            const Point2 p{random::uniform_in(x0, x1, seed, purpose_cut_x, cut, attempt),
                           random::uniform_in(y0, y1, seed, purpose_cut_y, cut, attempt)};
            if (!contains(poly, p)) continue;
            const double angle = random::uniform_in(0.0, std::numbers::pi, seed, purpose_cut_angle, cut, attempt);
            auto parts = split_convex(poly, p, {std::cos(angle), std::sin(angle)}, min_gap_units);
            if (!parts) continue;
            auto& [left, right] = *parts;
            if (left.size() > max_plate_vertices || right.size() > max_plate_vertices) continue;
            if (std::min(signed_area(left), signed_area(right)) < 0.25 * area) continue;
            polys[largest] = std::move(left);
            polys.push_back(std::move(right));
            done = true;
        }
        if (!done)
            throw Error("could not cut plate " + std::to_string(largest) + " into two convex plates of at most " +
                        std::to_string(max_plate_vertices) + " vertices; ask for fewer plates");
    }
    std::vector<PlateSpec> plates;
    for (std::size_t i = 0; i < polys.size(); ++i) {
        PlateSpec s;
        s.polygon = std::move(polys[i]);
        const bool oceanic = random::uniform(seed, purpose_oceanic, i) < oceanic_fraction;
        // ±0.02 around the crust's density, so two plates of a kind still differ a little.
        s.density = (oceanic ? oceanic_density : continental_density) +
            random::uniform_in(-0.02, 0.02, seed, purpose_density, i);
        const double angle = random::uniform_in(0.0, 2.0 * std::numbers::pi, seed, purpose_velocity_angle, i);
        const double v = speed * random::uniform(seed, purpose_velocity_size, i);
        s.velocity = {v * std::cos(angle), v * std::sin(angle)};
        s.angular_velocity = 0.0;
        plates.push_back(std::move(s));
    }
    return plates;
}

Result simulate(std::span<const PlateSpec> plates, const Params& params, std::uint64_t seed, const Layers& layers,
                const std::function<void(std::int64_t)>& on_step) {
    return simulate(plates, params, seed, layers, on_step, 0, {});
}

namespace {

void validate(std::span<const PlateSpec> plates, const Params& params, int width, int height) {
    if (width < 2 || height < 2) throw BadInput("the plate simulation needs a heightmap of at least 2 × 2 samples");
    if (params.steps < 1) throw BadInput("steps must be at least 1, got " + std::to_string(params.steps));
    if (!(params.dt > 0.0) || !std::isfinite(params.dt))
        throw BadInput("dt must be a positive number of seconds, got " + std::to_string(params.dt));
    if (params.stroke < 0.0 || params.stroke > margin_units)
        throw BadInput("stroke must lie in [0, " + std::to_string(margin_units) + "] u");
    if (plates.empty()) throw BadInput("the plate simulation needs at least one plate");
    for (std::size_t i = 0; i < plates.size(); ++i) {
        const Polygon& p = plates[i].polygon;
        if (p.size() > std::size_t(max_plate_vertices) || !is_convex_ccw(p))
            throw BadInput("plate " + std::to_string(i) + " must be a convex counter-clockwise polygon of 3 to " +
                           std::to_string(max_plate_vertices) + " vertices");
        for (std::size_t k = 0; k < p.size(); ++k) {
            const Point2 e = p[(k + 1) % p.size()] - p[k];
            if (std::hypot(e.x, e.y) < min_gap_units)
                throw BadInput("plate " + std::to_string(i) + " has an edge shorter than " +
                               std::to_string(min_gap_units).substr(0, 4) + " u, which Box2D would weld away");
        }
    }
}

Result run_simulation(std::span<const PlateSpec> plates, const Params& params, std::uint64_t seed, const Layers& layers,
                      const std::function<void(std::int64_t)>& on_step, std::int64_t snapshot_every,
                      const SnapshotFn& on_snapshot) {
    validate(plates, params, layers.terrain.width, layers.terrain.height);
    Simulation sim(params, seed, layers);
    sim.add_beams();
    for (std::size_t i = 0; i < plates.size(); ++i) sim.add_plate(plates[i], int(i));
    sim.next_id_ = int(plates.size());
    double total_area = 0.0;
    for (const PlateSpec& p : plates) total_area += signed_area(p.polygon);
    sim.set_min_rift_part(0.5 * total_area / double(plates.size()));
    return sim.run(on_step, snapshot_every, on_snapshot);
}

}  // namespace

Result simulate(std::span<const PlateSpec> plates, const Params& params, std::uint64_t seed, const Layers& layers,
                const std::function<void(std::int64_t)>& on_step, std::int64_t snapshot_every,
                const SnapshotFn& on_snapshot) {
    if (!layers.terrain.data) throw BadInput("the plate simulation needs a heightmap of at least 2 × 2 samples");
    return run_simulation(plates, params, seed, layers, on_step, snapshot_every, on_snapshot);
}

Result simulate_events(std::span<const PlateSpec> plates, const Params& params, std::uint64_t seed, int width,
                       int height, double cell, const std::function<void(std::int64_t)>& on_step) {
    Layers none;
    none.terrain = GridView{nullptr, width, height, cell};
    return run_simulation(plates, params, seed, none, on_step, 0, {});
}

void draw_tile(const Replay& replay, const Params& params, std::uint64_t seed, const Layers& layers, TileRect tile,
               std::int64_t snapshot_every, const SnapshotFn& on_snapshot) {
    const int w = replay.width, h = replay.height;
    if (!layers.terrain.data || layers.terrain.width != tile.width || layers.terrain.height != tile.height ||
        tile.x0 < 0 || tile.y0 < 0 || tile.x1() > w || tile.y1() > h)
        throw BadInput("draw_tile: the terrain must hold the tile, and the tile lie inside the simulation's grid");
    // The relief's activity fields over the tile and the margin its volcanoes reach across.
    const ReliefShape shape = relief_shape(params, w, h);
    const std::uint64_t relief_seed = random::hash(seed, purpose_relief);
    const int m = BoundaryRelief(w, h, TileRect{0, 0, 1, 1}, shape, relief_seed).vent_margin();
    const int x0 = std::max(0, tile.x0 - m), y0 = std::max(0, tile.y0 - m);
    const TileRect window{x0, y0, std::min(w, tile.x1() + m) - x0, std::min(h, tile.y1() + m) - y0};
    BoundaryRelief relief(w, h, window, shape, relief_seed);
    GridView uplift = layers.uplift;
    GridView* up = uplift.data ? &uplift : nullptr;
    std::size_t drawn = 0;
    auto draw_until = [&](std::int64_t step) {  // the stamps come in the order of their steps
        for (; drawn < replay.stamps.size() && replay.stamps[drawn].step <= step; ++drawn)
            draw_stamp(replay.stamps[drawn], params, relief, layers.terrain, up, tile);
    };
    if (on_snapshot && snapshot_every > 0) {
        // As Simulation::run: after every snapshot_every-th step but the last, the terrain with the relief so far.
        std::vector<float> scratch;
        const GridView& t = layers.terrain;
        for (std::int64_t step = snapshot_every; step < params.steps; step += snapshot_every) {
            draw_until(step);
            scratch.assign(t.data, t.data + t.size());
            GridView copy{scratch.data(), t.width, t.height, t.cell};
            relief.apply(copy, tile);
            on_snapshot(step, copy);
        }
    }
    draw_until(std::numeric_limits<std::int64_t>::max());
    relief.apply(layers.terrain, tile, up);
    draw_layers(replay, layers, tile);
}

// ------------------------------------------------------------- the replay's bytes

namespace {

constexpr char kReplayMagic[8] = {'o', 'r', 'p', 'l', 'a', 't', 'e', '2'};

template <typename T>
void put(std::string& out, const T& v) {
    out.append(reinterpret_cast<const char*>(&v), sizeof v);
}

struct Reader {
    std::string_view bytes;
    std::size_t at = 0;
    template <typename T>
    T get() {
        if (bytes.size() - at < sizeof(T)) throw Error("internal error: a plate replay ends early");
        T v;
        std::memcpy(&v, bytes.data() + at, sizeof v);
        at += sizeof v;
        return v;
    }
    std::size_t count(std::size_t each) {
        const auto n = get<std::uint64_t>();
        if (each > 0 && n > (bytes.size() - at) / each) throw Error("internal error: a plate replay ends early");
        return std::size_t(n);
    }
};

}  // namespace

std::string encode(const Replay& r) {
    std::string out(kReplayMagic, sizeof kReplayMagic);
    put(out, std::int32_t(r.width));
    put(out, std::int32_t(r.height));
    put(out, r.cell);
    put(out, std::uint64_t(r.stamps.size()));
    for (const ReliefStamp& s : r.stamps) {
        put(out, std::uint8_t(s.kind));
        put(out, s.a.x), put(out, s.a.y), put(out, s.b.x), put(out, s.b.y);
        put(out, s.toward_light.x), put(out, s.toward_light.y);
        put(out, s.seed);
        put(out, s.step);
    }
    put(out, std::uint64_t(r.boundaries.size()));
    for (const CollisionEvent& e : r.boundaries) {
        put(out, e.step), put(out, std::int32_t(e.plate_a)), put(out, std::int32_t(e.plate_b));
        put(out, e.a.x), put(out, e.a.y), put(out, e.b.x), put(out, e.b.y);
        put(out, std::uint8_t(e.kind)), put(out, e.impulse);
    }
    put(out, std::uint64_t(r.final_polygons.size()));
    for (std::size_t i = 0; i < r.final_polygons.size(); ++i) {
        put(out, std::int32_t(r.final_ids[i]));
        put(out, std::uint64_t(r.final_polygons[i].size()));
        for (const Point2& p : r.final_polygons[i]) put(out, p.x), put(out, p.y);
    }
    return out;
}

Replay decode_replay(std::string_view bytes) {
    Reader in{bytes};
    if (bytes.size() < sizeof kReplayMagic || std::memcmp(bytes.data(), kReplayMagic, sizeof kReplayMagic) != 0)
        throw Error("internal error: not a plate replay");
    in.at = sizeof kReplayMagic;
    Replay r;
    r.width = in.get<std::int32_t>();
    r.height = in.get<std::int32_t>();
    r.cell = in.get<double>();
    r.stamps.resize(in.count(1 + 6 * 8 + 8 + 8));
    for (ReliefStamp& s : r.stamps) {
        s.kind = ReliefStamp::Kind(in.get<std::uint8_t>());
        s.a.x = in.get<double>(), s.a.y = in.get<double>(), s.b.x = in.get<double>(), s.b.y = in.get<double>();
        s.toward_light.x = in.get<double>(), s.toward_light.y = in.get<double>();
        s.seed = in.get<std::uint64_t>();
        s.step = in.get<std::int64_t>();
    }
    r.boundaries.resize(in.count(8 + 4 + 4 + 4 * 8 + 1 + 8));
    for (CollisionEvent& e : r.boundaries) {
        e.step = in.get<std::int64_t>();
        e.plate_a = in.get<std::int32_t>(), e.plate_b = in.get<std::int32_t>();
        e.a.x = in.get<double>(), e.a.y = in.get<double>(), e.b.x = in.get<double>(), e.b.y = in.get<double>();
        e.kind = BoundaryKind(in.get<std::uint8_t>());
        e.impulse = in.get<double>();
    }
    const std::size_t n = in.count(4 + 8);
    r.final_polygons.resize(n);
    r.final_ids.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        r.final_ids[i] = in.get<std::int32_t>();
        r.final_polygons[i].resize(in.count(16));
        for (Point2& p : r.final_polygons[i]) p.x = in.get<double>(), p.y = in.get<double>();
    }
    if (in.at != bytes.size()) throw Error("internal error: a plate replay has bytes after its end");
    return r;
}

// ------------------------------------------------------------- rasterising

void draw_segment(GridView layer, Point2 a, Point2 b, float value, int radius) {
    draw_segment(layer, TileRect{0, 0, layer.width, layer.height}, a, b, value, radius);
}

void fill_polygon(GridView layer, std::span<const Point2> polygon, float value) {
    fill_polygon(layer, TileRect{0, 0, layer.width, layer.height}, polygon, value);
}

void draw_segment(GridView layer, TileRect at, Point2 a, Point2 b, float value, int radius) {
    int x0 = int(std::lround(a.x)), y0 = int(std::lround(a.y));
    const int x1 = int(std::lround(b.x)), y1 = int(std::lround(b.y));
    const int dx = std::abs(x1 - x0), dy = -std::abs(y1 - y0);
    const int sx = x0 < x1 ? 1 : -1, sy = y0 < y1 ? 1 : -1;
    int err = dx + dy;
    for (;;) {
        for (int oy = -radius; oy <= radius; ++oy)
            for (int ox = -radius; ox <= radius; ++ox) {
                const int x = x0 + ox, y = y0 + oy;
                if (x >= at.x0 && x < at.x1() && y >= at.y0 && y < at.y1()) layer.at(x - at.x0, y - at.y0) = value;
            }
        if (x0 == x1 && y0 == y1) break;
        const int e2 = 2 * err;
        if (e2 >= dy) err += dy, x0 += sx;
        if (e2 <= dx) err += dx, y0 += sy;
    }
}

void fill_polygon(GridView layer, TileRect at, std::span<const Point2> polygon, float value) {
    if (polygon.size() < 3) return;
    double ymin = polygon[0].y, ymax = ymin;
    for (const Point2& v : polygon) ymin = std::min(ymin, v.y), ymax = std::max(ymax, v.y);
    const int y0 = std::max(at.y0, int(std::ceil(ymin))), y1 = std::min(at.y1() - 1, int(std::floor(ymax)));
    if (y0 > y1) return;
    parallel_for(y0, y1 + 1, 64, [&](std::int64_t r0, std::int64_t r1) {
        for (std::int64_t y = r0; y < r1; ++y) {
            // A convex polygon meets a row in one interval: intersect the row with every edge.
            double lo = 1e300, hi = -1e300;
            const std::size_t n = polygon.size();
            for (std::size_t i = 0; i < n; ++i) {
                const Point2 p = polygon[i], q = polygon[(i + 1) % n];
                if ((p.y <= double(y) && q.y >= double(y)) || (q.y <= double(y) && p.y >= double(y))) {
                    const double x =
                        p.y == q.y ? std::min(p.x, q.x) : p.x + (double(y) - p.y) * (q.x - p.x) / (q.y - p.y);
                    const double x2 = p.y == q.y ? std::max(p.x, q.x) : x;
                    lo = std::min(lo, x), hi = std::max(hi, x2);
                }
            }
            const int x0 = std::max(at.x0, int(std::ceil(lo))), x1 = std::min(at.x1() - 1, int(std::floor(hi)));
            for (int x = x0; x <= x1; ++x) layer.at(x - at.x0, int(y) - at.y0) = value;
        }
    });
}

}  // namespace orogen::plates
