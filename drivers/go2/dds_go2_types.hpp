// The idlc-generated C types of the Go2 (unitree_go::msg::dds_, unitree_api::msg::dds_), built
// from drivers/go2/idl/*.idl into ${PROJECT_BINARY_DIR}/generated/go2_idl/ by drivers/CMakeLists.
#pragma once

#include "go2_idl/LowState_.h"
#include "go2_idl/Request_.h"
#include "go2_idl/Response_.h"
#include "go2_idl/SportModeState_.h"
