#include "ontime/domains/task_planner.hpp"

#include <igraph/igraph.h>

#include <cmath>
#include <mutex>
#include <stdexcept>

#include "ontime/domains/library_messages.hpp"

namespace ontime::domains {
namespace {

std::array<double, 2> centre(const Room& room) {
  return {(room.min_x + room.max_x) / 2, (room.min_y + room.max_y) / 2};
}

double distance(const std::array<double, 2>& a, double x, double y) { return std::hypot(a[0] - x, a[1] - y); }

// The weight of door `door` between rooms a and b: centre of a, through the door, to the centre of b.
double door_weight(const NavigationWorld& world, const Door& door) {
  return distance(centre(world.room(door.rooms[0])), door.x, door.y) +
         distance(centre(world.room(door.rooms[1])), door.x, door.y);
}

// igraph's containers, freed on every path out.
struct Graph {
  igraph_t graph{};
  explicit Graph(const igraph_vector_int_t& edges, igraph_integer_t vertices) {
    if (igraph_create(&graph, &edges, vertices, IGRAPH_UNDIRECTED) != IGRAPH_SUCCESS) {
      throw std::runtime_error("igraph could not build the room graph");
    }
  }
  ~Graph() { igraph_destroy(&graph); }
  Graph(const Graph&) = delete;
  Graph& operator=(const Graph&) = delete;
};

struct IntVector {
  igraph_vector_int_t vector{};
  explicit IntVector(igraph_integer_t size) {
    if (igraph_vector_int_init(&vector, size) != IGRAPH_SUCCESS) throw std::bad_alloc();
  }
  ~IntVector() { igraph_vector_int_destroy(&vector); }
  IntVector(const IntVector&) = delete;
  IntVector& operator=(const IntVector&) = delete;
};

struct RealVector {
  igraph_vector_t vector{};
  explicit RealVector(igraph_integer_t size) {
    if (igraph_vector_init(&vector, size) != IGRAPH_SUCCESS) throw std::bad_alloc();
  }
  ~RealVector() { igraph_vector_destroy(&vector); }
  RealVector(const RealVector&) = delete;
  RealVector& operator=(const RealVector&) = delete;
};

struct PathList {
  igraph_vector_int_list_t list{};
  PathList() {
    if (igraph_vector_int_list_init(&list, 0) != IGRAPH_SUCCESS) throw std::bad_alloc();
  }
  ~PathList() { igraph_vector_int_list_destroy(&list); }
  PathList(const PathList&) = delete;
  PathList& operator=(const PathList&) = delete;
};

std::mutex& igraph_mutex() {
  static std::mutex mutex;
  return mutex;
}

// The room paths of one world, computed in batches of doubling size and shared by its planners.
class RoomPaths {
 public:
  RoomPaths(const NavigationWorld& world, int longest) : world_(&world), longest_(longest) {}

  // Path k (0-based), or nullptr when there are fewer paths.
  const std::vector<std::string>* path(std::size_t k) {
    const std::lock_guard lock(igraph_mutex());
    while (k >= paths_.size() && !complete_) grow();
    return k < paths_.size() ? &paths_[k] : nullptr;
  }

 private:
  void grow() {
    const int wanted = std::min<int>(longest_, std::max<int>(8, 2 * static_cast<int>(paths_.size())));
    const auto rooms = static_cast<igraph_integer_t>(world_->rooms.size());
    const auto doors = static_cast<igraph_integer_t>(world_->doors.size());
    IntVector edges(2 * doors);
    RealVector weights(doors);
    for (igraph_integer_t d = 0; d < doors; ++d) {
      const Door& door = world_->doors[static_cast<std::size_t>(d)];
      VECTOR(edges.vector)[2 * d] = world_->room_index(door.rooms[0]);
      VECTOR(edges.vector)[2 * d + 1] = world_->room_index(door.rooms[1]);
      VECTOR(weights.vector)[d] = door_weight(*world_, door);
    }
    // igraph reports errors by return code once its default handler (which aborts) is off.
    igraph_set_error_handler(igraph_error_handler_ignore);
    detail::route_igraph_messages();  // its warnings, through OnTime (handlers are per thread)
    const Graph graph(edges.vector, rooms);
    PathList found;
    if (igraph_get_k_shortest_paths(&graph.graph, &weights.vector, &found.list, nullptr, wanted,
                                    world_->room_index(world_->start_room), world_->room_index(world_->goal_room),
                                    IGRAPH_ALL) != IGRAPH_SUCCESS) {
      throw std::runtime_error("igraph could not compute the room paths of " + world_->name);
    }
    const igraph_integer_t count = igraph_vector_int_list_size(&found.list);
    std::vector<std::vector<std::string>> paths;
    for (igraph_integer_t p = 0; p < count; ++p) {
      const igraph_vector_int_t* vertices = igraph_vector_int_list_get_ptr(&found.list, p);
      std::vector<std::string> moves;
      for (igraph_integer_t v = 1; v < igraph_vector_int_size(vertices); ++v) {
        moves.push_back("move(" + world_->rooms[static_cast<std::size_t>(VECTOR(*vertices)[v - 1])].id + "," +
                        world_->rooms[static_cast<std::size_t>(VECTOR(*vertices)[v])].id + ")");
      }
      paths.push_back(std::move(moves));
    }
    // A larger batch begins with the smaller one (same graph, same order), so the paths handed out
    // stay the same.
    complete_ = count < wanted || wanted >= longest_;
    paths_ = std::move(paths);
  }

  const NavigationWorld* world_;
  int longest_;
  std::vector<std::vector<std::string>> paths_;
  bool complete_ = false;
};

class RoomPathPlanner final : public TaskPlanner {
 public:
  explicit RoomPathPlanner(std::shared_ptr<RoomPaths> paths) : paths_(std::move(paths)) {}
  void restart() override { next_ = 0; }
  std::optional<std::vector<std::string>> next() override {
    const std::vector<std::string>* path = paths_->path(next_);
    if (path == nullptr) return std::nullopt;
    ++next_;
    return *path;
  }

 private:
  std::shared_ptr<RoomPaths> paths_;
  std::size_t next_ = 0;
};

class FixedSkeletonPlanner final : public TaskPlanner {
 public:
  explicit FixedSkeletonPlanner(const Domain& domain) : domain_(&domain) {}
  void restart() override { next_ = 0; }
  std::optional<std::vector<std::string>> next() override {
    if (next_ >= domain_->skeletons().size()) return std::nullopt;
    return domain_->skeletons()[next_++];
  }

 private:
  const Domain* domain_;
  std::size_t next_ = 0;
};

}  // namespace

TaskPlannerFactory room_path_planners(const NavigationWorld& world, int longest) {
  if (longest < 1) throw std::invalid_argument("a task planner must be allowed at least one skeleton");
  if (world.room_index(world.start_room) < 0 || world.room_index(world.goal_room) < 0) {
    throw std::invalid_argument("the world's start and goal rooms must be rooms of it");
  }
  auto paths = std::make_shared<RoomPaths>(world, longest);
  return [paths] { return std::make_unique<RoomPathPlanner>(paths); };
}

TaskPlannerFactory fixed_skeleton_planners(const Domain& domain) {
  return [&domain] { return std::make_unique<FixedSkeletonPlanner>(domain); };
}

TaskPlannerFactory Domain::task_planners(int /*max_skeletons*/) const { return fixed_skeleton_planners(*this); }

std::vector<std::array<double, 2>> Domain::skeleton_points(const std::vector<std::string>& /*skeleton*/) const {
  return {};
}

namespace {

// The door a move goes through: of the doors joining its rooms, the one of least weight.
const Door& door_of(const NavigationWorld& world, const std::string& move) {
  const std::vector<std::string> rooms = move_rooms(move);
  if (rooms.size() != 2) throw std::invalid_argument("'" + move + "' is not move(FROM,TO)");
  const Door* best = nullptr;
  for (const Door& door : world.doors) {
    const bool joins = (door.rooms[0] == rooms[0] && door.rooms[1] == rooms[1]) ||
                       (door.rooms[0] == rooms[1] && door.rooms[1] == rooms[0]);
    if (joins && (best == nullptr || door_weight(world, door) < door_weight(world, *best))) best = &door;
  }
  if (best == nullptr) throw std::invalid_argument("no door joins the rooms of '" + move + "'");
  return *best;
}

}  // namespace

double room_path_length(const NavigationWorld& world, const std::vector<std::string>& moves) {
  double length = 0;
  for (const std::string& move : moves) length += door_weight(world, door_of(world, move));
  return length;
}

std::vector<std::array<double, 2>> room_path_points(const NavigationWorld& world,
                                                    const std::vector<std::string>& moves) {
  std::vector<std::array<double, 2>> points{{world.start.x, world.start.y}};
  for (const std::string& move : moves) {
    const Door& door = door_of(world, move);
    points.push_back({door.x, door.y});
    points.push_back(centre(world.room(move_rooms(move)[1])));
  }
  return points;
}

}  // namespace ontime::domains
