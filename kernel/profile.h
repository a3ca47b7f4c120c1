// Where a run's time goes (`iblcheck run --profile`, issue 33): code marks its stages with a scoped
// `ProfileStage`, and each thread's wall time is split between the stages it was in. Stages nest;
// a stage's figure is its own (exclusive) time: while a nested stage runs, its parent's clock
// stops, so a test's stages add up to its wall time. Off (the default) a stage costs one atomic
// load; nothing is recorded.
#pragma once
#include <map>
#include <string>

namespace iblcheck::profile {

// Turns recording on or off for every thread (before the workers start).
void enable(bool on);
bool enabled();

// Seconds per stage this thread spent since the last take() (or since it started), exclusive of
// nested stages; clears them. Time in no stage is not counted: a caller that wants the rest names
// it with an outer stage.
std::map<std::string, double> take();

} // namespace iblcheck::profile

namespace iblcheck {

class ProfileStage {
  public:
    explicit ProfileStage(const char* name);
    ~ProfileStage();
    ProfileStage(const ProfileStage&) = delete;
    ProfileStage& operator=(const ProfileStage&) = delete;

  private:
    bool active_;
};

} // namespace iblcheck
