// Watches a Gmsh run's terminal output, line by line, for a run that makes no progress.
//
// Gmsh 4.8 meshes curves, then surfaces, then volumes, and says so on its terminal ("Meshing
// surface 3 (Cylinder, Frontal-Delaunay)"). When elements of a surface stay invalid it refines
// the surface's edges and meshes it again ("N elements remain invalid in surface 3",
// "Serializing surface 3 and refining all its bounding edges"). On some models (sizes far above
// a curve's radius) the number of invalid elements grows with each round, each round takes
// twice as long as the one before, and the run only ends at its time budget (600 s). Two rises
// in a row are taken as such a stall; so is a surface entered more often than a successful run
// enters one. The stall is named by the CAD face it is on.
//
// The watch also passes Gmsh's messages on to stderr as the user's verbosity asks (warnings and
// errors at 1, information at 2), and any other line as it is (at 1); it learns which CAD face and
// edge each Gmsh entity is from the lines gmshEntityLine writes.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace homesh {

class GmshProgressWatch {
 public:
  // Entries of one surface taken as a stall (twice the most seen in a successful run).
  static constexpr int kStallEntries = 12;

  // `givenNames`: as LinearMeshOptions::givenNames, added to the CAD entity a message names.
  explicit GmshProgressWatch(int verbosity,
                             std::function<std::string(int dim, int index)> givenNames = {})
      : verbosity_(verbosity), givenNames_(std::move(givenNames)) {}

  // One line of the run's output (without its newline). Returns "" while the run progresses;
  // once it stalls, what it stalled on: "Gmsh's surface 1 (CAD face 3): its invalid elements
  // rose from 16 to 56 to 234 as Gmsh refined its edges" ("(CAD face 3; as given: Face7)" where
  // the model was numbered afresh).
  std::string operator()(const std::string& line);

  // What Gmsh was doing when its output ended, for a crash's message: "while meshing Gmsh's
  // surface 38 (CAD face 40), after its error: The 1D mesh seems not to be forming a closed
  // loop" (the entity it last entered, and an error said since), or "" when it said nothing of
  // it (between entities: the volumes' meshing says which volume it enters only in 3D).
  std::string lastActivity() const;

 private:
  std::string name(int dim, int tag) const;
  std::string seeMessage(const std::string& message);

  int verbosity_;
  std::function<std::string(int dim, int index)> givenNames_;
  std::map<std::pair<int, int>, int> cad_;    // Gmsh (dim, tag) -> CAD number
  std::map<int, int> entries_;                // Gmsh surface tag -> times entered
  std::map<int, std::vector<long>> invalid_;  // Gmsh surface tag -> invalid counts so far
  std::pair<int, int> current_{-1, 0};        // the entity last entered (dim, tag)
  std::string lastError_;
};

// The line that tells a watch that Gmsh entity (dim, tag) is CAD sub-shape `cadIndex` (its
// face, edge or solid number, from 1).
std::string gmshEntityLine(int dim, int tag, int cadIndex);

}  // namespace homesh
