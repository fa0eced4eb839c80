# Tests that keep a CPU busy for most of their run (pure computation, or hundreds of ASan process
# starts): each counts as 2 of ctest's job slots, so at most half of `-j` runs them at once and the
# other slots go to tests that wait on sockets and child processes. Without it the longest-first
# order started them together (4 jobs per CPU) and they timed out on a 2-vCPU machine.
# A name that no longer exists is ignored. Read by ctest (test/schedule/CMakeLists.txt).
foreach(_t
    "json:element JSON plan: broken element trees render as the general path or are declined, never otherwise"
    "json:element JSON plan: nesting beyond Limits::max_nesting_depth is declined, as the general path refuses it"
    "json:json: every value unpacked from a corrupted element round-trips through JSON"
    "core:message: single-byte mutations of every vector never crash, and what decodes round-trips"
    "core:message: nesting deeper than Limits::max_nesting_depth is a ProtocolError"
    "core:message: a stream of every vector splits anywhere and yields each message in order"
    "core:unpack survives corrupted elements, what it accepts packs again"
    "test support: rr_core_tests [shared] cases skip without the shared data"
    "docs: deployment.md steps run"
    "cli: rr -> our service" "cli: rr -> official service" "cli: rr -> reynard"
    "cli: rr -> our service (rr+local)" "cli: rr -> official service (rr+local)"
    "cli: rr -> gateway -> our service" "cli: rr -> gateway (rr+ws) -> our service"
    "cli: rr -> gateway (rr+local) -> our service"
    "wasm-client: npm pack, tsc --noEmit, usage.ts against the demo devices")
  set_tests_properties("${_t}" PROPERTIES PROCESSORS 2)
endforeach()
