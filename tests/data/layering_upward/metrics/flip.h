#pragma once
#include "harness/suite.h"
