// Declares builtin_scenes() (defined in the generated builtin_scenes.cpp); see scene.hpp.
#pragma once
#include "tools/sim/scene.hpp"
