#include "metrics/flip.h"
#include "renderers/vulkan/context.h"
