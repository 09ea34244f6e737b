// SkeletonExtraction: a skeleton for bark that comes without one (third-party glTF trees), for the
// lines of the ellipsoids-and-lines paper (001) §3.2, which start from "the imported skeleton".
//
// This work is based on:
//   Anne Verroust, Francis Lazarus, "Extracting skeletal curves from 3D scattered data", The Visual
//   Computer 16(1), 2000 (level sets of the geodesic distance from a root over a neighbourhood graph;
//   the centroid of each connected piece of a level set is a skeleton node).
//   Hui Xu, Nathan Gossett, Baoquan Chen, "Knowledge and heuristic-based modeling of laser-scanned
//   trees", ACM Transactions on Graphics 26(4), 2007 (the same on trees: distance bins from the base,
//   parents across bins).
// Chosen over a medial-axis or mesh-contraction skeleton because tree bark is a set of tubes, often
// disconnected and open-ended, where level sets of the distance along the surface are rings whose
// centroids lie on the tube's axis; it needs no watertight mesh and is O(V log V).
//
//   1. Weld: bark vertices within 1e-6 of the bark box's diagonal D are one (glTF tubes are split at
//      UV seams). Degenerate triangles (degenerateTriangle) after welding are left out: they cannot
//      be seen, and a sliver would join vertices that no visible surface joins.
//   2. The edge graph of the triangles and its connected components (the tubes). The component with
//      the lowest vertex (the trunk) comes first, then the others by surface area, largest first, so
//      a branch's tube is placed before its twigs'.
//   3. Root of a component: the trunk's is its lowest vertex. Another component's is its vertex
//      nearest the skeleton built so far (the distance to the surface of a segment's capsule, as the
//      lines draw it) when that is within 0.01 D; the component then hangs off the nearer
//      end node of that segment. Otherwise its lowest vertex, and it is a root of its own (the stems
//      of a shrub). Sources: the root's boundary loop (an open tube end) when the root lies on one,
//      else the root alone.
//   4. Geodesic distance d (Dijkstra over the edges) from the sources. The sources are band 0; band
//      k >= 1 holds 1 + floor(d / w) = k, w = 2 times the mean distance of the sources from their
//      centroid (the tube's radius at its base), at least 0.005 D.
//   5. A node per connected piece of a band (edges inside the band), at the centroid of its vertices.
//      Its parent is the piece of the Dijkstra predecessor of its entry vertex (its vertex of least
//      d whose predecessor lies outside it), always in an earlier band. Radius: the mean distance of
//      its vertices from the axis through the centroid along the direction from the parent node (to
//      the first child for a component's first node; from the centroid when there is neither) — not
//      from the centroid, which would count a band's length along the tube as radius.
//   6. Tips: a piece without children gets a child node at the centroid of its farthest vertices
//      (d within w / 4 of its largest) when that lies more than w / 4 from the piece's centroid: the
//      apex of a tube's end cone (radius 0) or its open end ring, so that the lines reach the end.
// Handles a single tube (a chain), one triangle (one node), degenerate and duplicate triangles,
// and disconnected tubes (ez-tree style). Measured on the generated oak, conifer, birch and shrub
// (seeds 1, 2) with their skeletons removed: 99 % of the nodes within 0.9 of the local radius of the
// generator's skeleton, all within 0.005 D; 11 ms for the oak's 12k bark triangles, 4 to 11 ms for
// five ez-tree presets (3k to 12k). Deterministic (no threads, ties broken by vertex index); every
// tolerance is relative to D, so the result scales with the tree.
#pragma once

#include "TreeLod/TreeModel.h"

#include <glm/glm.hpp>

#include <vector>

namespace TreeLod
{
    /// Whether a bark triangle is left out as degenerate: a corner is not finite, or its area is at
    /// most 1e-6 of its longest edge squared (a point, or a sliver under 2e-6 as high as it is long).
    bool degenerateTriangle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c);

    /// The skeleton the lines start from: model.skeleton when it has nodes, else extractSkeleton(model).
    std::vector<SkeletonNode> barkSkeleton(const TreeModel& model);

    /// The skeleton of `model`'s bark by the steps above (model.skeleton is ignored). Parents before
    /// children, positions finite, radii finite and >= 0; empty when every bark triangle is degenerate.
    /// Bark indices out of range and non-finite positions are skipped.
    std::vector<SkeletonNode> extractSkeleton(const TreeModel& model);
}
