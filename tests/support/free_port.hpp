#pragma once
// A free loopback TCP port for tests that start a server process: the one of the bench drivers.

#include "edm/apps/free_port.hpp"

namespace edm::test {
using edm::apps::free_port;
}  // namespace edm::test
