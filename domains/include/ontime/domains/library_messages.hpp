#pragma once
// Messages of the libraries the domains call (OMPL's console, igraph's warnings), routed through
// OnTime rather than printed raw on standard error: each goes to the sink set here, which the
// program chooses (the ontime tool prints warnings and errors once each, as `ontime: OMPL
// warning: ...`); with no sink they are dropped. OMPL's debug and information messages are
// dropped before they are formatted. The sink may be called from any thread, concurrently.

#include <functional>
#include <string_view>

namespace ontime::domains {

enum class LibraryMessageLevel { warning, error };

using LibraryMessageSink =
    std::function<void(std::string_view library, LibraryMessageLevel level, std::string_view text)>;

// Replaces the sink (empty: drop every message). Thread-safe.
void set_library_message_sink(LibraryMessageSink sink);

namespace detail {
// Installs the routes: OMPL's output handler (once per process) and igraph's warning handler
// (igraph keeps its handlers per thread: call it on the thread that calls igraph, before it).
void route_ompl_messages();
void route_igraph_messages();
}  // namespace detail

}  // namespace ontime::domains
