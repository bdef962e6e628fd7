// SPDX-License-Identifier: Apache-2.0
// An image that calls nothing, linked with every external symbol of one library forced in (the
// build passes -u for each): so that any path in settle_core, settle_hal or settle_servo that
// reaches the heap, exception support or a libc function a bare board lacks fails the cross
// build, before an image ever calls it.
#include "settle/firmware/runtime.hpp"

int settle::firmware::image_main() { return 0; }
