#include "ccsrm/identify/run_journal.h"

#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <utility>

#include "ccsrm/common/digest.h"
#include "ccsrm/common/error.h"
#include "run_codec.h"

namespace ccsrm::identify {

namespace {

// A record cut short, or written over, does not pass its checksum.
std::uint64_t Checksum(const std::vector<char>& bytes) {
  Fnv1aDigest digest;
  digest.Add(bytes.data(), bytes.size());
  return digest.value();
}

struct Record {
  std::vector<char> request;  // internal::PutRequest's bytes, after the set
  std::vector<char> result;   // internal::PutResult's
};

}  // namespace

struct RunJournal::Impl {
  std::vector<Record> records;
  std::size_t next = 0;  // the next record to replay
  std::int64_t simulated = 0;
  std::FILE* file = nullptr;
};

RunJournal::RunJournal(const std::string& path, bool resume)
    : path_(path), impl_(std::make_unique<Impl>()) {
  std::int64_t valid_bytes = 0;
  if (resume) {
    std::ifstream in(path, std::ios::binary);
    std::error_code ec;
    const std::uintmax_t file_size = std::filesystem::file_size(path, ec);
    for (;;) {
      std::uint64_t size = 0, sum = 0;
      if (!in.read(reinterpret_cast<char*>(&size), sizeof(size))) break;
      if (!in.read(reinterpret_cast<char*>(&sum), sizeof(sum))) break;
      // A size the rest of the file cannot hold is a torn or garbled tail:
      // checked before anything is allocated for it.
      const std::uint64_t left =
          ec ? 0 : file_size - static_cast<std::uint64_t>(valid_bytes) - 2 * sizeof(std::uint64_t);
      if (size < sizeof(std::uint64_t) || size > left) break;
      std::vector<char> bytes(static_cast<std::size_t>(size));
      if (!in.read(bytes.data(), static_cast<std::streamsize>(size)) || Checksum(bytes) != sum) {
        break;  // cut short by a kill: this record and anything after it
      }
      internal::Unpacker unpack(bytes);
      const std::uint64_t request_size = unpack.Get<std::uint64_t>();
      if (request_size > size - sizeof(std::uint64_t)) break;
      Record r;
      r.request.resize(request_size);
      r.result.resize(bytes.size() - sizeof(std::uint64_t) - r.request.size());
      std::memcpy(r.request.data(), bytes.data() + sizeof(std::uint64_t), r.request.size());
      std::memcpy(r.result.data(), bytes.data() + sizeof(std::uint64_t) + r.request.size(),
                  r.result.size());
      impl_->records.push_back(std::move(r));
      valid_bytes += static_cast<std::int64_t>(2 * sizeof(std::uint64_t) + size);
    }
  }
  // Keep the valid records, drop a torn tail, append from there.
  impl_->file = std::fopen(path.c_str(), resume ? "r+b" : "wb");
  if (impl_->file == nullptr && resume) impl_->file = std::fopen(path.c_str(), "wb");
  if (impl_->file == nullptr) ThrowInputError(path, "", "cannot be written");
  if (ftruncate(fileno(impl_->file), valid_bytes) != 0 ||
      std::fseek(impl_->file, valid_bytes, SEEK_SET) != 0) {
    ThrowInputError(path, "", "cannot be written");
  }
}

RunJournal::~RunJournal() {
  if (impl_->file != nullptr) std::fclose(impl_->file);
}

std::int64_t RunJournal::recorded() const {
  return static_cast<std::int64_t>(impl_->records.size());
}
std::int64_t RunJournal::replayed() const { return static_cast<std::int64_t>(impl_->next); }
std::int64_t RunJournal::simulated() const { return impl_->simulated; }

class JournaledBackend final : public SimulationBackend {
 public:
  JournaledBackend(std::shared_ptr<SimulationBackend> inner, std::shared_ptr<RunJournal> journal,
                   int set)
      : inner_(std::move(inner)), journal_(std::move(journal)), set_(set) {}

  int parallelism() const override { return inner_->parallelism(); }

  std::vector<RunResult> RunBatch(const std::vector<RunRequest>& requests,
                                  const RunFinishedCallback& on_finished) override {
    RunJournal::Impl& j = *journal_->impl_;
    std::vector<RunResult> results(requests.size());
    std::vector<std::vector<char>> keys(requests.size());
    std::vector<RunRequest> to_run;
    std::vector<std::size_t> to_run_index;
    std::size_t done = 0;
    for (std::size_t k = 0; k < requests.size(); ++k) {
      internal::Packer key;
      key.Put<std::int32_t>(set_);
      internal::PutRequest(requests[k], &key);
      keys[k] = std::move(key.bytes());
      if (!requests[k].keep_trajectory && j.next < j.records.size()) {
        const Record& r = j.records[j.next];
        if (r.request != keys[k]) {
          ThrowInputError(journal_->path(), "run " + std::to_string(j.next + 1),
                          "the recorded run is not the one asked for: the journal is of "
                          "another command line; refusing to resume");
        }
        ++j.next;
        internal::Unpacker in(r.result);
        results[k] = internal::GetResult(&in);
        ++done;
        if (on_finished) on_finished(done, requests.size(), results[k]);
        continue;
      }
      to_run.push_back(requests[k]);
      to_run_index.push_back(k);
    }
    if (to_run.empty()) return results;
    const std::vector<RunResult> ran =
        inner_->RunBatch(to_run, [&](std::size_t, std::size_t, const RunResult& r) {
          ++done;
          if (on_finished) on_finished(done, requests.size(), r);
        });
    j.simulated += static_cast<std::int64_t>(ran.size());
    for (std::size_t i = 0; i < ran.size(); ++i) {
      const std::size_t k = to_run_index[i];
      results[k] = ran[i];
      if (requests[k].keep_trajectory) continue;
      internal::Packer record;
      record.Put<std::uint64_t>(keys[k].size());
      record.Append(keys[k].data(), keys[k].size());
      internal::PutResult(ran[i], &record);
      const std::uint64_t size = record.bytes().size();
      const std::uint64_t sum = Checksum(record.bytes());
      std::fwrite(&size, sizeof(size), 1, j.file);
      std::fwrite(&sum, sizeof(sum), 1, j.file);
      std::fwrite(record.bytes().data(), 1, record.bytes().size(), j.file);
    }
    // On disk before the command goes on: a kill loses at most the batch in flight.
    if (std::fflush(j.file) != 0 || fsync(fileno(j.file)) != 0) {
      ThrowInputError(journal_->path(), "", "cannot be written");
    }
    return results;
  }

 private:
  std::shared_ptr<SimulationBackend> inner_;
  std::shared_ptr<RunJournal> journal_;
  int set_;
};

std::shared_ptr<SimulationBackend> WithJournal(std::shared_ptr<SimulationBackend> inner,
                                               std::shared_ptr<RunJournal> journal, int set) {
  return std::make_shared<JournaledBackend>(std::move(inner), std::move(journal), set);
}

}  // namespace ccsrm::identify
