#pragma once
#include "kernel/errors.h"
