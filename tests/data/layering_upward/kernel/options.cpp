#include "../kernel/errors.h"
