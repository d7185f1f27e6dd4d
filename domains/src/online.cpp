#include "ontime/domains/online.hpp"

#include <chrono>
#include <memory>
#include <string>

#include "ontime/evaluation.hpp"
#include "ontime/fitting.hpp"
#include "ontime/random.hpp"
#include "ontime/session.hpp"
#include "parallel.hpp"

namespace ontime::domains {

OnlineEpisode run_online_episode(const Domain& domain, const Mdp& mdp, Allocator& allocator, std::uint64_t seed,
                                 const OnlineOptions& options) {
  const Problem& problem = mdp.problem();
  const double step = problem.step_seconds();
  struct Progress {
    std::unique_ptr<Refinement> refinement;
    Steps spent = 0;
  };
  std::vector<Progress> actions(static_cast<std::size_t>(problem.action_count()));
  OnlineEpisode episode;
  Session session(mdp, allocator);
  while (session.status() == Status::running) {
    const Decision decision = session.choose();
    if (decision.action < 0) {
      session.report_not_yet();  // an idle step
      continue;
    }
    Progress& progress = actions[static_cast<std::size_t>(decision.action)];
    if (!progress.refinement) {
      const int parent = problem.parent(decision.action);
      const std::string& id = problem.action(decision.action).id;
      const auto stream = 2 * static_cast<std::uint64_t>(decision.action);
      Configuration start;
      if (parent < 0) {
        start = domain.initial_configuration();
      } else if (options.independent_starts) {
        start = domain.fallback_start(id, stream_seed(seed, stream + 1));
      } else {
        start = actions[static_cast<std::size_t>(parent)].refinement->final_configuration();
      }
      progress.refinement = domain.refine(id, start, stream_seed(seed, stream), options.effort);
      ++episode.actions_started;
    }
    ++progress.spent;
    if (progress.refinement->advance(static_cast<double>(progress.spent) * step) == RefinementStatus::found) {
      ++episode.actions_refined;
      session.report_refined(steps_to_complete(progress.refinement->execution_seconds(), step));
    } else {
      session.report_not_yet();
    }
  }
  episode.status = session.status();
  episode.solution = session.solution();
  episode.steps_used = session.steps_used();
  return episode;
}

OnlineSummary run_online(const Domain& domain, const Mdp& mdp, const AllocatorFactory& factory,
                         std::uint64_t episodes, std::uint64_t seed, unsigned threads, const OnlineOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  std::vector<OnlineEpisode> results(episodes);
  detail::for_each_index(episodes, threads, [&] {
    return [&, allocator = std::shared_ptr<Allocator>(factory())](std::uint64_t e) {
      results[e] = run_online_episode(domain, mdp, *allocator, stream_seed(seed, e), options);
    };
  });
  OnlineSummary summary;
  summary.episodes = episodes;
  double started_total = 0;
  for (const OnlineEpisode& episode : results) {
    summary.successes += episode.status == Status::success ? 1 : 0;
    started_total += episode.actions_started;
  }
  summary.success_rate = episodes > 0 ? static_cast<double>(summary.successes) / static_cast<double>(episodes) : 0.0;
  summary.ci95 = ci95_half_width(summary.success_rate, episodes);
  summary.mean_actions_started = episodes > 0 ? started_total / static_cast<double>(episodes) : 0.0;
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return summary;
}

}  // namespace ontime::domains
