// Placement areas: exclusions and free area, shared by the parser (a density's tree count)
// and the sampling in Placement.cpp. Private to TreeLodScript.
#pragma once

#include "TreeLod/SceneScript.h"

#include <vector>

namespace TreeLod::SceneScriptDetail
{
    bool excluded(const std::vector<SceneArea>& exclude, const glm::vec2& p);

    /// Area of `area` outside the exclusions, in m²: exact without exclusions, otherwise
    /// the fraction of 512 x 512 cell centres of the bounding box that are free.
    double freeArea(const SceneArea& area, const std::vector<SceneArea>& exclude);
}
