// Precompiled, after the headers of its layer, for the test executables
// (cmake/TreeLodStableHeaders.cmake).
#pragma once

#include <gtest/gtest.h>
