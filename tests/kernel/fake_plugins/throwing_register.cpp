// A plugin whose registration callback throws: reported, the other plugins still load.
#include <orogen/plugin.hpp>

#include <stdexcept>

OROGEN_PLUGIN("test-register-throws", "0.0.1", registry) {
    (void)registry;
    throw std::runtime_error("cannot find my data files");
}
