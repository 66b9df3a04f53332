// model_node.hpp — the run of a node whose body is erode:stream-power's model (stream_power.hpp): the
// whole grid's Model, or under mpirun this rank's tile of a TiledModel (tiled.hpp: the same bits), with
// its uplift, base level, time-lapse, progress, finiteness checks and layers. erode:stream-power runs
// it; erode:evolve runs it for a body of the built-in processes under mpirun (processes.hpp).
#pragma once

#include "stream_power.hpp"
#include "uplift.hpp"

#include <orogen/node.hpp>

namespace orogen::landscape {

struct ModelRun {
    Settings settings;
    UpliftSources uplift;
    bool chi = false;  ///< also the layer chi
};

/// Reads the node's `years`, `dt`, `timelapse_every` and `base_level`, its terrain (input 0) and uplift
/// history (input 1, optional); returns the evolved terrain with the layers drainage, flow_direction,
/// eroded, uplifted (and ice_flux, rain, chi as the settings ask) and the time-lapse side value.
NodeOutputs run_model(NodeContext& ctx, const ModelRun& run);

}  // namespace orogen::landscape
