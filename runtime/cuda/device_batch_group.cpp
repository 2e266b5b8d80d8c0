// DeviceBatch::step_together: several batches stepped with one launch pair per code (GroupPlan).
#include <algorithm>
#include <map>
#include <string>

#include "runtime/cuda/device_batch.h"
#include "runtime/cuda/group_plan.h"
#include "runtime/cuda/render_plan.h"

namespace kage {
namespace {

/// Lets this thread make a plan (allocate, copy, create streams) while a stream capture is under way on it
/// (a CUDA graph's first call): the plan's work is ordered on a stream of its own, outside the capture.
class RelaxedCapture {
 public:
  RelaxedCapture() : mode_(CU_STREAM_CAPTURE_MODE_RELAXED) { cuThreadExchangeStreamCaptureMode(&mode_); }
  ~RelaxedCapture() { cuThreadExchangeStreamCaptureMode(&mode_); }
  RelaxedCapture(const RelaxedCapture&) = delete;
  RelaxedCapture& operator=(const RelaxedCapture&) = delete;

 private:
  CUstreamCaptureMode mode_;
};

/// Copies `bytes` from host memory to `device` on a stream of its own and waits for it.
bool upload(CUdeviceptr device, const void* host, size_t bytes, std::string* error) {
  CUstream stream = nullptr;
  if (!cu_check(cuStreamCreate(&stream, CU_STREAM_NON_BLOCKING), "cuStreamCreate", error)) return false;
  const bool ok = cu_check(cuMemcpyHtoDAsync(device, host, bytes, stream), "cuMemcpyHtoDAsync(group rows)", error) &&
                  cu_check(cuStreamSynchronize(stream), "cuStreamSynchronize", error);
  cuStreamDestroy(stream);
  return ok;
}

}  // namespace

GroupPlan::~GroupPlan() {
  // Frees fail only once the context is gone at exit, when the memory is released anyway.
  if (rows) cuMemFree(rows);
  for (const GroupLaunch& l : launches) {
    if (l.done) cuEventDestroy(l.done);
    if (l.stream) cuStreamDestroy(l.stream);
  }
  for (CUevent e : queued) cuEventDestroy(e);
  if (entered) cuEventDestroy(entered);
  if (fork) cuEventDestroy(fork);
  if (stepped) cuEventDestroy(stepped);
}

GroupPlan* DeviceBatch::group_plan(const std::vector<DeviceBatch*>& batches, std::string* error) {
  std::vector<uint64_t> serials;
  for (const DeviceBatch* b : batches) serials.push_back(b->serial_);
  for (const std::unique_ptr<GroupPlan>& plan : plans_)
    if (plan->serials == serials) return plan.get();

  // The rows code by code, in the order the codes first appear; a part without a code is a launch of its own.
  std::vector<std::string> order;
  std::map<std::string, std::vector<std::pair<const Part*, GroupRow>>> by_code;
  for (size_t i = 0; i < batches.size(); ++i)
    for (const Part& p : batches[i]->parts_) {
      if (p.envs.num_envs == 0) continue;
      const std::string key = p.code.empty() ? "#" + std::to_string(order.size()) : p.code;
      if (!by_code.count(key)) order.push_back(key);
      by_code[key].push_back({&p, GroupRow{p.envs, static_cast<int32_t>(i), p.first}});
    }
  RelaxedCapture relaxed;
  auto plan = std::make_unique<GroupPlan>();
  plan->serials = serials;
  std::vector<GroupRow> rows;
  for (const std::string& key : order) {
    const auto& members = by_code[key];
    const Part& p = *members.front().first;
    GroupLaunch l;
    l.step_rows = p.step_rows;
    l.render = p.render;
    l.first_row = static_cast<int32_t>(rows.size());
    l.row_count = static_cast<int32_t>(members.size());
    l.render_threads = p.render_threads;
    l.render_smem = p.render_smem;
    int64_t total = 0;
    for (const auto& [part, row] : members) {
      rows.push_back(row);
      l.max_envs = std::max(l.max_envs, part->envs.num_envs);
      total += part->envs.num_envs;
    }
    l.frames_per_block = frames_per_block(p.frame_passes, static_cast<int32_t>(std::min<int64_t>(total, INT32_MAX)),
                                          multiprocessors_);
    plan->launches.push_back(l);
  }
  const size_t bytes = std::max<size_t>(rows.size(), 1) * sizeof(GroupRow);
  if (!cu_check(cuMemAlloc(&plan->rows, bytes), "cuMemAlloc(group rows)", error) ||
      (!rows.empty() && !upload(plan->rows, rows.data(), rows.size() * sizeof(GroupRow), error)))
    return nullptr;
  if (plan->launches.size() > 1)
    for (GroupLaunch& l : plan->launches)
      if (!cu_check(cuStreamCreate(&l.stream, CU_STREAM_NON_BLOCKING), "cuStreamCreate", error) ||
          !cu_check(cuEventCreate(&l.done, CU_EVENT_DISABLE_TIMING), "cuEventCreate", error))
        return nullptr;
  plan->queued.assign(batches.size(), nullptr);
  for (CUevent* e : {&plan->entered, &plan->fork, &plan->stepped})
    if (!cu_check(cuEventCreate(e, CU_EVENT_DISABLE_TIMING), "cuEventCreate", error)) return nullptr;
  for (CUevent& e : plan->queued)
    if (!cu_check(cuEventCreate(&e, CU_EVENT_DISABLE_TIMING), "cuEventCreate", error)) return nullptr;
  plans_.push_back(std::move(plan));
  return plans_.back().get();
}

bool DeviceBatch::step_together(const std::vector<DeviceBatch*>& batches, const ActionRows& actions,
                                std::string* error) {
  if (batches.empty()) {
    *error = "DeviceBatch::step_together: no batches";
    return false;
  }
  DeviceBatch& lead = *batches.front();
  GroupPlan* plan = lead.group_plan(batches, error);
  if (!plan) return false;
  const CUstream main = lead.stream_;
  // After the work queued so far on every batch's stream (a consumer of its last outputs, its reset). The
  // other streams first wait for the lead's (the actions' producer ordered itself before it): under a stream
  // capture that brings them into the capture, whose streams may only wait for captured work.
  if (!cu_check(cuEventRecord(plan->entered, main), "cuEventRecord", error)) return false;
  for (size_t i = 1; i < batches.size(); ++i)
    if (batches[i]->stream_ != main &&
        !(cu_check(cuStreamWaitEvent(batches[i]->stream_, plan->entered, 0), "cuStreamWaitEvent", error) &&
          cu_check(cuEventRecord(plan->queued[i], batches[i]->stream_), "cuEventRecord", error) &&
          cu_check(cuStreamWaitEvent(main, plan->queued[i], 0), "cuStreamWaitEvent", error)))
      return false;
  const bool fork = plan->launches.size() > 1;
  if (fork && !cu_check(cuEventRecord(plan->fork, main), "cuEventRecord", error)) return false;
  for (const GroupLaunch& l : plan->launches) {
    const CUstream stream = fork ? l.stream : main;
    CUdeviceptr rows = plan->rows + static_cast<CUdeviceptr>(l.first_row) * sizeof(GroupRow);
    ActionRows source = actions;
    void* step_args[] = {&rows, &source};
    DeviceEnvs unused{};  // kage_render's own view, read only without rows
    void* render_args[] = {&rows, &unused};
    const auto rows_y = static_cast<unsigned>(l.row_count);
    const auto step_x = static_cast<unsigned>((l.max_envs + kPerEnvThreads - 1) / kPerEnvThreads);
    const auto render_x = static_cast<unsigned>((l.max_envs + l.frames_per_block - 1) / l.frames_per_block);
    if ((fork && !cu_check(cuStreamWaitEvent(stream, plan->fork, 0), "cuStreamWaitEvent", error)) ||
        !cu_check(cuLaunchKernel(l.step_rows, step_x, rows_y, 1, kPerEnvThreads, 1, 1, 0, stream, step_args, nullptr),
               "cuLaunchKernel(kage_step_rows)", error) ||
        !cu_check(cuLaunchKernel(l.render, render_x, rows_y, 1, static_cast<unsigned>(l.render_threads), 1, 1,
                              static_cast<unsigned>(l.render_smem), stream, render_args, nullptr),
               "cuLaunchKernel(kage_render)", error))
      return false;
    if (fork && !(cu_check(cuEventRecord(l.done, stream), "cuEventRecord", error) &&
                  cu_check(cuStreamWaitEvent(main, l.done, 0), "cuStreamWaitEvent", error)))
      return false;
  }
  // The other batches' streams after the step, so that their consumers see its outputs.
  if (!cu_check(cuEventRecord(plan->stepped, main), "cuEventRecord", error)) return false;
  for (size_t i = 1; i < batches.size(); ++i)
    if (batches[i]->stream_ != main && !cu_check(cuStreamWaitEvent(batches[i]->stream_, plan->stepped, 0),
                                              "cuStreamWaitEvent", error))
      return false;
  return true;
}

}  // namespace kage
