#include "ontime/domains/manipulation_generator.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numbers>
#include <optional>
#include <set>
#include <stdexcept>

#include "kitchen_reach.hpp"
#include "ontime/domains/manipulation_features.hpp"
#include "ontime/util/atomic_file.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/random.hpp"
#include "planar_geometry.hpp"

namespace ontime::domains {
namespace {

using detail::Point;
using std::numbers::pi;

// The paper kitchen's room (data/domains/manipulation.json): floor, walls, start.
constexpr double kFloorX = 6.0, kFloorY = 3.6;
// Tables along the back wall: 1.4 m x 0.7 m, tops 4 cm thick on four legs of 5 cm.
constexpr double kTableWidth = 1.4, kTopThickness = 0.04, kLeg = 0.05, kLegInset = 0.02;
constexpr double kTableHeightMin = 0.70, kTableHeightMax = 0.80;
// Object centres stand at most this deep from the front edge (the arm's reach from a base in
// front of the table), targets at least kTargetDepth (room for neighbours in front).
constexpr double kReachDepth = 0.45, kTargetDepth = 0.15;
// Footprints keep this much of the top around them; region rectangles (of centres) this much
// more, the largest object's half diagonal.
constexpr double kTopMargin = 0.02, kObjectRadius = 0.05;
// Objects at least this far apart; regions and objects this far from regions' rectangles.
constexpr double kObjectGap = 0.02, kRegionKeep = kObjectRadius + kObjectGap;
constexpr double kRegionSpacing = 2 * kObjectRadius + kObjectGap;
// Neighbours: the circles around target and neighbour this far apart.
constexpr double kClutterGapMin = 0.03, kClutterGapMax = 0.08;
// Targets this far apart (footprints), so that no target is close to another's neighbours.
constexpr double kTargetSpacing = 2 * kManipulationNeighbourRadius + 2 * kObjectRadius + kClutterGapMax;
constexpr int kPlacementTries = 300, kGroupTries = 20;

// To whole units of 1/scale metres: the double nearest the decimal, written as that decimal.
double rounded(double value, double scale) {
  const double result = std::round(value * scale) / scale;
  return result == 0.0 ? 0.0 : result;  // no "-0"
}
double mm(double value) { return rounded(value, 1000); }
double cm(double value) { return rounded(value, 100); }

std::string number(double value) {
  char text[32];
  const auto result = std::to_chars(text, text + sizeof text, value);
  return std::string(text, result.ptr);
}

// Built by appending (GCC 12 warns, wrongly, about "[" + std::string).
std::string list_text(std::initializer_list<double> values) {
  std::string text = "[";
  for (const double value : values) {
    if (text.size() > 1) text += ", ";
    text += number(value);
  }
  text += "]";
  return text;
}
std::string triple(double x, double y, double z) { return list_text({x, y, z}); }
std::string pair_text(double x, double y) { return list_text({x, y}); }

double uniform(SplitMix64& random, double low, double high) { return low + (high - low) * uniform01(random); }

std::size_t below(SplitMix64& random, std::size_t count) {
  return std::min(count - 1, static_cast<std::size_t>(uniform01(random) * static_cast<double>(count)));
}

// A scene that breaks a rule: drawn again.
struct Rejected {
  std::string rule;
};

struct Table {
  double min_x = 0, max_x = 0, height = 0;
  std::string name;
  int first_region = -1;
};

struct Region {
  std::size_t table = 0;
  double min_x = 0, min_y = 0, max_x = 0, max_y = 0;
};

struct Item {
  std::string kind, id;
  std::array<double, 3> size{};
  std::size_t table = 0;
  double x = 0, y = 0, yaw = 0;
  int target = -1;  // which target it is, or -1
  int owner = -1;   // the target a neighbour belongs to, or -1
  double radius() const { return std::hypot(size[0], size[1]) / 2; }
  std::vector<Point> footprint() const { return detail::rectangle_corners(Rectangle{x, y, size[0], size[1], yaw}); }
};

class KitchenGenerator {
 public:
  KitchenGenerator(const KitchenOptions& options, std::uint64_t seed) : options_(options), seed_(seed) {
    name_ = options.name.empty() ? "kitchen" : options.name;
    for (const std::string& wanted : options.classes) {
      for (const KitchenObjectClass& known : kitchen_object_classes()) {
        if (known.name == wanted) classes_.push_back(&known);
      }
    }
  }

  // The scene of stream `attempt` of the seed; Rejected when it breaks a rule.
  std::string draw(std::uint64_t attempt) {
    SplitMix64 random(stream_seed(seed_, attempt));
    tables_.clear();
    regions_.clear();
    items_.clear();
    place_tables(random);
    place_regions(random);
    place_objects(random);
    assign_goals(random);
    check_room();
    std::string text = write(attempt);
    std::optional<ManipulationWorld> world;
    try {
      world = parse_manipulation_world(text, "generated kitchen");
    } catch (const InputError& error) {
      // The rules hold by construction: a violation is a bug here, not a scene to draw again.
      throw std::logic_error(std::string("the generated kitchen breaks the world file's rules: ") + error.what());
    }
    check_reach(*world, stream_seed(seed_, attempt));
    return text;
  }

 private:
  static constexpr double kFront = 2.9;  // the tables' front edge: kFloorY less their depth, 0.7 m

  void place_tables(SplitMix64& random) {
    const auto count = static_cast<std::size_t>(options_.tables);
    for (std::size_t t = 0; t < count; ++t) {
      const double centre = kFloorX * (static_cast<double>(t) + 0.5) / static_cast<double>(count);
      tables_.push_back(Table{cm(centre - kTableWidth / 2), cm(centre + kTableWidth / 2),
                              cm(uniform(random, kTableHeightMin, kTableHeightMax)), "table " + std::to_string(t + 1)});
    }
  }

  void place_regions(SplitMix64& random) {
    // Round the tables in a random order: every table gets one before any gets two.
    std::vector<std::size_t> order(tables_.size());
    for (std::size_t t = 0; t < order.size(); ++t) order[t] = t;
    for (std::size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[below(random, i)]);
    for (int r = 0; r < options_.regions; ++r) {
      const std::size_t t = order[static_cast<std::size_t>(r) % order.size()];
      const Table& table = tables_[t];
      const double width = cm(uniform(random, options_.region_min, options_.region_max));
      const double depth = cm(uniform(random, options_.region_min, options_.region_max));
      bool placed = false;
      for (int attempt = 0; attempt < kPlacementTries && !placed; ++attempt) {
        Region region{t, cm(uniform(random, table.min_x + kRegionKeep, table.max_x - kRegionKeep - width)),
                      cm(uniform(random, kFront + kRegionKeep, kFront + kReachDepth - depth)), 0, 0};
        region.max_x = cm(region.min_x + width);
        region.max_y = cm(region.min_y + depth);
        if (region.min_x < table.min_x + kRegionKeep - 1e-9 || region.max_x > table.max_x - kRegionKeep + 1e-9 ||
            region.min_y < kFront + kRegionKeep - 1e-9) {
          continue;
        }
        placed = std::all_of(regions_.begin(), regions_.end(), [&](const Region& other) {
          return other.table != t || detail::convex_distance(shape(region), shape(other)) >= kRegionSpacing;
        });
        if (placed) regions_.push_back(region);
      }
      if (!placed) throw Rejected{"no room on " + table.name + " for region R" + std::to_string(r + 1)};
      if (tables_[t].first_region < 0) tables_[t].first_region = r;
    }
  }

  static std::vector<Point> shape(const Region& region) {
    return detail::box_corners(region.min_x, region.min_y, region.max_x, region.max_y);
  }

  // An object of a class drawn among the options', its size and yaw drawn; placed later, and
  // named once every object has its place in the file (place_objects).
  Item new_item(SplitMix64& random) const {
    const KitchenObjectClass& kind = *classes_[below(random, classes_.size())];
    Item item;
    item.kind = kind.name;
    const double side = mm(uniform(random, kind.side_min, kind.side_max));
    item.size = {side, kind.square ? side : mm(uniform(random, kind.side_min, kind.side_max)),
                 mm(uniform(random, kind.height_min, kind.height_max))};
    item.yaw = cm(uniform(random, -pi, pi));
    return item;
  }

  // The tables that hold a region (the objects' "on" must name one).
  std::vector<std::size_t> furnished() const {
    std::vector<std::size_t> result;
    for (std::size_t t = 0; t < tables_.size(); ++t) {
      if (tables_[t].first_region >= 0) result.push_back(t);
    }
    return result;
  }

  // On its table's top with kTopMargin to spare, within reach, clear of the regions and of the
  // other objects.
  bool fits(const Item& item, double depth_min) const {
    const Table& table = tables_[item.table];
    if (item.y - kFront < depth_min || item.y - kFront > kReachDepth) return false;
    const std::vector<Point> outline = item.footprint();
    for (const Point& p : outline) {
      if (p[0] < table.min_x + kTopMargin || p[0] > table.max_x - kTopMargin || p[1] < kFront + kTopMargin ||
          p[1] > kFloorY - kTopMargin) {
        return false;
      }
    }
    for (const Region& region : regions_) {
      if (region.table == item.table && detail::convex_distance(outline, shape(region)) < kRegionKeep) return false;
    }
    for (const Item& other : items_) {
      if (other.table == item.table && detail::convex_distance(outline, other.footprint()) < kObjectGap) return false;
    }
    return true;
  }

  static double gap_to(const Item& item, const Item& other) {
    return item.table != other.table ? 1e9 : detail::convex_distance(item.footprint(), other.footprint());
  }

  // Target t, away from the targets before it (and their neighbours).
  bool place_target(SplitMix64& random, std::size_t t, const std::vector<std::size_t>& tables) {
    Item item = new_item(random);
    item.target = static_cast<int>(t);
    for (int attempt = 0; attempt < kPlacementTries; ++attempt) {
      item.table = tables[below(random, tables.size())];
      item.x = mm(uniform(random, tables_[item.table].min_x, tables_[item.table].max_x));
      item.y = mm(uniform(random, kFront + kTargetDepth, kFront + kReachDepth));
      if (fits(item, kTargetDepth) && std::all_of(items_.begin(), items_.end(), [&](const Item& other) {
            return other.target >= 0 ? gap_to(item, other) >= kTargetSpacing
                                     : gap_to(item, other) > kManipulationNeighbourRadius;
          })) {
        items_.push_back(item);
        return true;
      }
    }
    return false;
  }

  // `count` neighbours of the target just placed: beside it or in front of it, close to it and to
  // no other target.
  bool place_neighbours(SplitMix64& random, std::size_t t, std::size_t count) {
    const Item target = items_.back();
    for (std::size_t k = 0; k < count; ++k) {
      Item item = new_item(random);
      item.owner = static_cast<int>(t);
      item.table = target.table;
      bool placed = false;
      for (int attempt = 0; attempt < kPlacementTries && !placed; ++attempt) {
        const double angle = uniform(random, -pi, 0.0);
        const double distance = uniform(random, kClutterGapMin, kClutterGapMax) + target.radius() + item.radius();
        item.x = mm(target.x + distance * std::cos(angle));
        item.y = mm(target.y + distance * std::sin(angle));
        placed = fits(item, 0.0) && gap_to(item, target) <= kManipulationNeighbourRadius &&
                 std::all_of(items_.begin(), items_.end(), [&](const Item& other) {
                   return other.target < 0 || other.target == target.target ||
                          gap_to(item, other) > kManipulationNeighbourRadius;
                 });
      }
      if (!placed) return false;
      items_.push_back(item);
    }
    return true;
  }

  void place_objects(SplitMix64& random) {
    const auto fewest = static_cast<std::size_t>(options_.min_objects);
    const std::size_t count = fewest + below(random, static_cast<std::size_t>(options_.max_objects) - fewest + 1);
    const auto targets = static_cast<std::size_t>(options_.targets);
    const std::vector<std::size_t> tables = furnished();
    std::vector<std::size_t> clutter(targets);
    for (std::size_t t = 0; t < targets; ++t) {
      const auto least = static_cast<std::size_t>(options_.min_clutter);
      clutter[t] = least + below(random, static_cast<std::size_t>(options_.max_clutter) - least + 1);
    }
    // Each target with its neighbours; a target whose neighbours find no room is drawn again
    // elsewhere.
    for (std::size_t t = 0; t < targets; ++t) {
      const std::size_t before = items_.size();
      bool placed = false;
      for (int group = 0; group < kGroupTries && !placed; ++group) {
        items_.resize(before);
        placed = place_target(random, t, tables) && place_neighbours(random, t, clutter[t]);
      }
      if (!placed) throw Rejected{"no room on the tables for target " + std::to_string(t + 1) + " and its neighbours"};
    }
    // The others, away from every target.
    while (items_.size() < count) {
      Item item = new_item(random);
      bool placed = false;
      for (int attempt = 0; attempt < kPlacementTries && !placed; ++attempt) {
        item.table = tables[below(random, tables.size())];
        item.x = mm(uniform(random, tables_[item.table].min_x, tables_[item.table].max_x));
        item.y = mm(uniform(random, kFront, kFront + kReachDepth));
        placed = fits(item, 0.0) && std::all_of(items_.begin(), items_.end(), [&](const Item& other) {
                   return other.target < 0 || gap_to(item, other) > kManipulationNeighbourRadius;
                 });
      }
      if (!placed) throw Rejected{"no room on the tables for object " + std::to_string(items_.size() + 1)};
      items_.push_back(item);
    }
    // In the file: the targets first, then the neighbours, then the others; named by class and
    // place.
    std::vector<Item> ordered;
    for (std::size_t t = 0; t < targets; ++t) {
      ordered.push_back(*std::find_if(items_.begin(), items_.end(),
                                      [t](const Item& item) { return item.target == static_cast<int>(t); }));
    }
    for (const Item& item : items_) {
      if (item.owner >= 0) ordered.push_back(item);
    }
    for (const Item& item : items_) {
      if (item.owner < 0 && item.target < 0) ordered.push_back(item);
    }
    for (std::size_t i = 0; i < ordered.size(); ++i) ordered[i].id = ordered[i].kind + std::to_string(i + 1);
    items_ = std::move(ordered);
  }

  // Each target's goal region; each neighbour's destination, the region nearest to it other than
  // its target's goal; each target's neighbours, nearest first.
  void assign_goals(SplitMix64& random) {
    const auto targets = static_cast<std::size_t>(options_.targets);
    goals_.assign(targets, 0);
    neighbours_.assign(targets, {});
    destination_.assign(items_.size(), -1);
    for (std::size_t t = 0; t < targets; ++t) {
      goals_[t] = static_cast<int>(below(random, regions_.size()));
      destination_[t] = goals_[t];
    }
    for (std::size_t i = targets; i < items_.size(); ++i) {
      if (items_[i].owner < 0) continue;
      const auto t = static_cast<std::size_t>(items_[i].owner);
      neighbours_[t].push_back(i);
      double nearest = 0;
      for (std::size_t r = 0; r < regions_.size(); ++r) {
        if (static_cast<int>(r) == goals_[t] && regions_.size() > 1) continue;
        const double distance = regions_[r].table != items_[i].table
                                    ? 1e9 + std::abs(regions_[r].min_x - items_[i].x)
                                    : detail::convex_distance(items_[i].footprint(), shape(regions_[r]));
        if (destination_[i] < 0 || distance < nearest) {
          destination_[i] = static_cast<int>(r);
          nearest = distance;
        }
      }
    }
    for (std::size_t t = 0; t < targets; ++t) {
      std::stable_sort(neighbours_[t].begin(), neighbours_[t].end(), [&](std::size_t a, std::size_t b) {
        return gap_to(items_[a], items_[t]) < gap_to(items_[b], items_[t]);
      });
    }
  }

  // The objects the skeletons may place in region r, all at once: a grid of their circles fits.
  void check_room() const {
    for (std::size_t r = 0; r < regions_.size(); ++r) {
      std::size_t count = 0;
      double widest = 0;
      for (std::size_t i = 0; i < items_.size(); ++i) {
        if (destination_[i] != static_cast<int>(r)) continue;
        ++count;
        widest = std::max(widest, 2 * items_[i].radius());
      }
      if (count == 0) continue;
      const double pitch = widest + kObjectGap;
      const Region& region = regions_[r];
      const auto across = static_cast<std::size_t>(std::floor((region.max_x - region.min_x) / pitch + 1e-9)) + 1;
      const auto deep = static_cast<std::size_t>(std::floor((region.max_y - region.min_y) / pitch + 1e-9)) + 1;
      if (across * deep < count) {
        throw Rejected{"region R" + std::to_string(r + 1) + " has room for " + std::to_string(across * deep) +
                       " objects, and " + std::to_string(count) + " may be placed there"};
      }
    }
  }

  void check_reach(const ManipulationWorld& world, std::uint64_t seed) const {
    for (std::size_t i = 0; i < world.objects.size(); ++i) {
      if (!detail::can_pick(world, i, stream_seed(seed, i))) throw Rejected{"no base pose reaches " + items_[i].id};
    }
    for (std::size_t i = 0; i < items_.size(); ++i) {
      if (destination_[i] < 0) continue;
      const auto r = static_cast<std::size_t>(destination_[i]);
      if (!detail::can_place(world, i, r, stream_seed(seed, 1000 + i))) {
        throw Rejected{"no base pose places " + items_[i].id + " in R" + std::to_string(r + 1)};
      }
    }
  }

  std::vector<std::vector<std::string>> skeletons() const {
    std::vector<std::vector<std::string>> result;
    const auto targets = static_cast<std::size_t>(options_.targets);
    std::vector<std::size_t> cleared(targets, 0);  // an odometer, the first target outermost
    for (;;) {
      std::vector<std::string> skeleton;
      std::vector<std::string> context;
      const auto move = [&](std::size_t item, int region) {
        std::string suffix;
        for (const std::string& id : context) suffix += (suffix.empty() ? "[" : ",") + id;
        if (!suffix.empty()) suffix += "]";
        const std::string& id = items_[item].id;
        skeleton.push_back("move+pick(" + id + ")" + suffix);
        skeleton.push_back("move+place(" + id + ",R" + std::to_string(region + 1) + ")" + suffix);
        context.push_back(id);
      };
      for (std::size_t t = 0; t < targets; ++t) {
        for (std::size_t k = 0; k < cleared[t]; ++k) move(neighbours_[t][k], destination_[neighbours_[t][k]]);
        move(t, goals_[t]);
      }
      result.push_back(skeleton);
      std::size_t t = targets;
      while (t > 0 && cleared[t - 1] == neighbours_[t - 1].size()) cleared[--t] = 0;
      if (t == 0) break;
      ++cleared[t - 1];
    }
    return result;
  }

  std::string description(std::uint64_t attempt) const {
    std::string goal;
    const auto targets = static_cast<std::size_t>(options_.targets);
    for (std::size_t t = 0; t < targets; ++t) {
      goal += std::string(t == 0             ? ""
                          : t + 1 == targets ? " and "
                                             : ", ") +
              items_[t].id + " to R" + std::to_string(goals_[t] + 1) + " (" + std::to_string(neighbours_[t].size()) +
              (neighbours_[t].size() == 1 ? " neighbour)" : " neighbours)");
    }
    std::string classes;
    for (const std::string& kind : options_.classes) classes += (classes.empty() ? "" : ", ") + kind;
    return "Generated kitchen (seed " + std::to_string(seed_) + ", draw " + std::to_string(attempt + 1) +
           "): " + std::to_string(tables_.size()) + " tables along the back wall, " + std::to_string(regions_.size()) +
           " placement regions of " + number(options_.region_min) + "-" + number(options_.region_max) + " m, " +
           std::to_string(items_.size()) + " objects (" + classes + "; " + std::to_string(options_.min_objects) + "-" +
           std::to_string(options_.max_objects) + " asked for, " + std::to_string(options_.min_clutter) + "-" +
           std::to_string(options_.max_clutter) + " neighbours a target). Bring " + goal +
           "; each skeleton clears the nearest neighbours of each target first, "
           "none to all of them. Robot, planner and collection settings are the paper kitchen's.";
  }

  std::string write(std::uint64_t attempt) const {
    std::string out = "{\n";
    out += "  \"name\": \"" + name_ + "\",\n";
    out += "  \"description\": \"" + description(attempt) + "\",\n";
    out += "  \"floor\": {\"min\": [0, 0], \"max\": " + pair_text(kFloorX, kFloorY) + "},\n";
    out += "  \"walls\": {\"thickness\": 0.1, \"height\": 2.0},\n";
    out +=
        "  \"robot\": {\n"
        "    \"base\": {\"size\": [0.668, 0.668, 0.33], \"linear_speed\": 1.0, \"angular_speed\": 1.0},\n"
        "    \"torso_lift\": 0.15,\n    \"arm_speed\": 0.5,\n    \"gripper_seconds\": 1.0,\n"
        "    \"clearance\": 0.01,\n    \"carry\": [0.5, 0.6, 1.0, -1.8, -2.8, -1.0, 2.8]\n  },\n";
    out += "  \"start\": {\"base\": [3.0, 1.5, 1.5708]},\n";
    out +=
        "  \"planner\": {\n"
        "    \"arm_range\": 0.8, \"arm_resolution\": 0.03,\n"
        "    \"base_range\": 1.0, \"base_resolution\": 0.02,\n"
        "    \"base_distance\": [0.45, 0.95], \"base_heading_spread\": 0.5, \"approach_distance\": 0.1,\n"
        "    \"ik_checks\": 30, \"target_checks\": 3000, \"placement_gap\": 0.005\n  },\n";
    out += "  \"collection\": {\"deadline\": " + std::to_string(20 * options_.targets) +
           ", \"step_seconds\": 7.0, \"checks_per_second\": 250},\n";
    out += "  \"fixed\": {\n";
    for (std::size_t t = 0; t < tables_.size(); ++t) {
      const Table& table = tables_[t];
      const double leg_top = cm(table.height - kTopThickness);
      out += "    \"" + table.name + "\": [\n";
      out += "      {\"min\": " + triple(table.min_x, kFront, leg_top) +
             ", \"max\": " + triple(table.max_x, kFloorY, table.height) + "}";
      for (const double x : {table.min_x + kLegInset, table.max_x - kLegInset - kLeg}) {
        for (const double y : {kFront + kLegInset, kFloorY - kLegInset - kLeg}) {
          out += ",\n      {\"min\": " + triple(cm(x), cm(y), 0) +
                 ", \"max\": " + triple(cm(x + kLeg), cm(y + kLeg), leg_top) + "}";
        }
      }
      out += std::string("\n    ]") + (t + 1 < tables_.size() ? ",\n" : "\n");
    }
    out += "  },\n  \"regions\": {\n";
    for (std::size_t r = 0; r < regions_.size(); ++r) {
      const Region& region = regions_[r];
      out += "    \"R" + std::to_string(r + 1) + "\": {\"on\": \"" + tables_[region.table].name +
             "\", \"height\": " + number(tables_[region.table].height) +
             ", \"min\": " + pair_text(region.min_x, region.min_y) +
             ", \"max\": " + pair_text(region.max_x, region.max_y) + "}" + (r + 1 < regions_.size() ? ",\n" : "\n");
    }
    out += "  },\n  \"objects\": {\n";
    for (std::size_t i = 0; i < items_.size(); ++i) {
      const Item& item = items_[i];
      out += "    \"" + item.id + "\": {\"size\": " + triple(item.size[0], item.size[1], item.size[2]) +
             ", \"on\": \"R" + std::to_string(tables_[item.table].first_region + 1) +
             "\", \"pose\": " + triple(item.x, item.y, item.yaw) + "}" + (i + 1 < items_.size() ? ",\n" : "\n");
    }
    out += "  },\n  \"goal\": {";
    for (std::size_t t = 0; t < goals_.size(); ++t) {
      out += std::string(t == 0 ? "" : ", ") + "\"" + items_[t].id + "\": \"R" + std::to_string(goals_[t] + 1) + "\"";
    }
    out += "},\n  \"skeletons\": [\n";
    const auto all = skeletons();
    for (std::size_t k = 0; k < all.size(); ++k) {
      out += "    [";
      for (std::size_t l = 0; l < all[k].size(); ++l) out += std::string(l == 0 ? "\"" : ", \"") + all[k][l] + "\"";
      out += std::string("]") + (k + 1 < all.size() ? ",\n" : "\n");
    }
    out += "  ]\n}\n";
    return out;
  }

  KitchenOptions options_;
  std::uint64_t seed_;
  std::string name_;
  std::vector<const KitchenObjectClass*> classes_;
  std::vector<Table> tables_;
  std::vector<Region> regions_;
  std::vector<Item> items_;
  std::vector<int> goals_;                            // by target: region index
  std::vector<std::vector<std::size_t>> neighbours_;  // by target, nearest first
  std::vector<int> destination_;                      // by item: region index, -1 when never moved
};

}  // namespace

const std::vector<KitchenObjectClass>& kitchen_object_classes() {
  static const std::vector<KitchenObjectClass> classes{{"cup", 0.055, 0.065, true, 0.08, 0.12},
                                                       {"box", 0.04, 0.065, false, 0.10, 0.20},
                                                       {"bottle", 0.05, 0.065, true, 0.20, 0.28}};
  return classes;
}

void check_kitchen_options(const KitchenOptions& options, const ParameterSpelling& spelling) {
  const auto name = [&spelling](std::string_view parameter) { return spell_parameter(spelling, parameter); };
  const auto count = [&](std::string_view parameter, int value, int low, int high) {
    if (value < low || value > high) {
      throw UsageError(name(parameter) + ": must be a whole number from " + std::to_string(low) + " to " +
                       std::to_string(high) + " (got " + std::to_string(value) + ")");
    }
  };
  const auto ordered = [&](std::string_view low_name, double low, std::string_view high_name, double high) {
    if (low > high) {
      throw UsageError(name(low_name) + " (" + number(low) + ") must not exceed " + name(high_name) + " (" +
                       number(high) + ")");
    }
  };
  count("tables", options.tables, 1, kMaxKitchenTables);
  count("regions", options.regions, 1, kMaxKitchenRegions);
  for (const auto& [parameter, value] :
       {std::pair{"region-min", options.region_min}, {"region-max", options.region_max}}) {
    if (!(value >= kMinKitchenRegionSide && value <= kMaxKitchenRegionSide)) {
      throw UsageError(name(parameter) + ": must be a finite number from " + number(kMinKitchenRegionSide) + " to " +
                       number(kMaxKitchenRegionSide) + " (got " + number(value) + ")");
    }
  }
  ordered("region-min", options.region_min, "region-max", options.region_max);
  count("targets", options.targets, 1, kMaxKitchenTargets);
  count("min-objects", options.min_objects, 1, kMaxKitchenObjects);
  count("max-objects", options.max_objects, 1, kMaxKitchenObjects);
  ordered("min-objects", options.min_objects, "max-objects", options.max_objects);
  count("min-clutter", options.min_clutter, 0, kMaxKitchenClutter);
  count("max-clutter", options.max_clutter, 0, kMaxKitchenClutter);
  ordered("min-clutter", options.min_clutter, "max-clutter", options.max_clutter);
  const int needed = options.targets * (1 + options.max_clutter);
  if (options.min_objects < needed) {
    throw UsageError(name("min-objects") + " (" + std::to_string(options.min_objects) + ") must be at least " +
                     name("targets") + " x (1 + " + name("max-clutter") + ") = " + std::to_string(needed) +
                     ": every target and its neighbours");
  }
  if (options.classes.empty()) throw UsageError(name("classes") + ": name at least one class (cup, box, bottle)");
  std::set<std::string> seen;
  for (const std::string& kind : options.classes) {
    const auto& known = kitchen_object_classes();
    if (std::none_of(known.begin(), known.end(), [&](const KitchenObjectClass& c) { return c.name == kind; })) {
      throw UsageError(name("classes") + ": unknown class '" + kind + "' (known: cup, box, bottle)");
    }
    if (!seen.insert(kind).second) throw UsageError(name("classes") + ": '" + kind + "' is named twice");
  }
  if (std::any_of(options.name.begin(), options.name.end(),
                  [](char c) { return c == '"' || c == '\\' || static_cast<unsigned char>(c) < 0x20; })) {
    throw UsageError(name("name") + ": must not contain quotes, backslashes or control characters");
  }
}

std::string generate_kitchen_text(const KitchenOptions& options, std::uint64_t seed,
                                  const ParameterSpelling& spelling) {
  check_kitchen_options(options, spelling);
  KitchenGenerator generator(options, seed);
  std::string last;
  for (int attempt = 0; attempt < kKitchenAttempts; ++attempt) {
    try {
      return generator.draw(static_cast<std::uint64_t>(attempt));
    } catch (const Rejected& rejected) {
      last = rejected.rule;
    }
  }
  throw UsageError("no feasible kitchen in " + std::to_string(kKitchenAttempts) +
                   " draws with these options (the last: " + last +
                   "); ask for fewer objects or neighbours, more or larger regions, or more tables");
}

ManipulationWorld generate_kitchen(const KitchenOptions& options, std::uint64_t seed) {
  ManipulationWorld world = parse_manipulation_world(generate_kitchen_text(options, seed), "generated kitchen");
  world.source = world.name;
  return world;
}

GeneratedKitchen write_generated_kitchen(const KitchenOptions& options, std::uint64_t seed,
                                         const std::filesystem::path& output, const ParameterSpelling& spelling) {
  const std::string text = generate_kitchen_text(options, seed, spelling);
  write_file_atomically(output, text);
  const ManipulationWorld world = parse_manipulation_world(text, output.string());
  std::set<std::string> actions;
  for (const auto& skeleton : world.skeletons) actions.insert(skeleton.begin(), skeleton.end());
  return GeneratedKitchen{
      output.string(),        world.name,     world.fixed.size(), world.regions.size(), world.objects.size(),
      world.skeletons.size(), actions.size(), world.goal};
}

}  // namespace ontime::domains
