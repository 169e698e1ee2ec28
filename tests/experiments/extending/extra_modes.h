#pragma once

// The registry line of a mode leglab does not ship (see registry.h): the libraries built for
// the extending test register it after the shipped modes.
#include "blend_controller.h"

#define LEGLAB_EXTRA_MODES , BlendController
