// The public header used from C++: it compiles, and its declarations link.
#include <tclod/tclod.h>

#include <cstdio>

int main() {
    tclod_selector_desc desc;
    tclod_selector_desc_default(&desc);
    if (tclod_version() != TCLOD_VERSION_NUMBER || desc.solver != TCLOD_SOLVER_GREEDY) {
        std::fprintf(stderr, "consumer_cxx: unexpected version or defaults\n");
        return 1;
    }
    std::printf("consumer_cxx: libtclod %s (%s)\n", tclod_version_string(),
                tclod_status_string(TCLOD_OK));
    return 0;
}
