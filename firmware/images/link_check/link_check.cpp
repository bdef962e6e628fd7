// An image that calls nothing, linked with every external symbol of settle_core forced in (the
// build passes -u for each): so that any path in core reaching the heap, exception support or a
// libc function a bare board lacks fails the cross build, before an image ever calls it.
#include "settle/firmware/runtime.hpp"

int settle::firmware::image_main() { return 0; }
