// BatchedChannel<T>: a Channel whose messages are batches of items per destination (the seed's
// packets of rays): a PE appends items to one outbox per destination, an outbox is sent as one
// message when it holds `batchSize` items, and every partial outbox is sent when the PE runs
// dry (flushIfDry). One message per batch instead of per item is what makes the partitioned
// tracers pay off: the lock, the doorbell and the handler's fixed cost are paid once per batch.
// Counting is the Channel's: one message per batch, its bytes its items' encodings (the
// batch's length travels in the envelope, its sender is the message's source).
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "common/parallel/channel.h"
#include "common/util/error.h"

namespace pr::par {

template <class T>
class BatchedChannel {
 public:
  using Batch = std::vector<T>;
  using Handler = std::function<void(Pe&, Batch&&)>;

  // batchSize >= 1 items per message. The handler runs on the receiving PE, once per batch.
  BatchedChannel(Runtime& runtime, std::string name, MessageKind kind, std::size_t batchSize, Handler handler)
      : batchSize_(batchSize),
        channel_(runtime, std::move(name), kind,
                 [this, handler = std::move(handler)](Pe& pe, Batch&& batch) {
                   handler(pe, std::move(batch));
                   recycle(pe, std::move(batch));
                 }),
        out_(size_t(runtime.pes())) {
    PR_CHECK(batchSize >= 1, "BatchedChannel: a batch holds at least one item");
    for (PeOutboxes& o : out_) o.boxes.resize(size_t(runtime.pes()));
  }

  // On PE `from`: queues the item for `to` and sends the batch when it is full.
  void send(Pe& from, int to, T item) {
    PeOutboxes& mine = out_[size_t(from.id())];
    Outbox& box = mine.boxes[size_t(to)];
    if (box.items.capacity() == 0) box.items = mine.storage(batchSize_);
    box.bytes += Wire<T>::size(item);
    box.items.push_back(std::move(item));
    if (box.items.size() >= batchSize_) sendBox(from, to, box);
  }

  // Whether a batch waits for pe (it will be handled before pe goes idle).
  bool pending(int pe) const { return channel_.pending(pe); }

  // On PE `from`: sends every partial batch. Call before the PE can go idle: an item left in
  // an outbox is not yet a message, so the stage could end without it.
  void flush(Pe& from) {
    std::vector<Outbox>& boxes = out_[size_t(from.id())].boxes;
    for (size_t to = 0; to < boxes.size(); ++to)
      if (!boxes[to].items.empty()) sendBox(from, int(to), boxes[to]);
  }

 private:
  struct Outbox {
    Batch items;
    std::size_t bytes = 0;
  };
  // Padded to a cache line: each PE writes only its own outboxes and spare storage.
  struct alignas(64) PeOutboxes {
    std::vector<Outbox> boxes;  // per destination
    // Emptied batches this PE handled, reused for the batches it sends: a batch is allocated
    // by one PE and freed by another, and recycling its storage spares the allocator both
    // (a free from another thread takes the allocating thread's arena lock).
    std::vector<Batch> spare;
    Batch storage(std::size_t capacity) {
      if (spare.empty()) {
        Batch b;
        b.reserve(capacity);
        return b;
      }
      Batch b = std::move(spare.back());
      spare.pop_back();
      return b;
    }
  };

  // The items' sizes were summed as they were queued: Wire<Batch>'s size, without a second pass.
  void sendBox(Pe& from, int to, Outbox& box) {
    const std::size_t bytes = box.bytes;
    channel_.sendEncoded(from, to, std::move(box.items), bytes);
    box.items = Batch();
    box.bytes = 0;
  }

  // On the receiving PE, after the handler: keeps the batch's storage (a handler that moved
  // the items out leaves none to keep). A few spares per destination cover what is in flight.
  void recycle(Pe& pe, Batch&& batch) {
    PeOutboxes& mine = out_[size_t(pe.id())];
    if (batch.capacity() < batchSize_ || mine.spare.size() >= 4 * mine.boxes.size()) return;
    batch.clear();
    mine.spare.push_back(std::move(batch));
  }

  std::size_t batchSize_;
  Channel<Batch> channel_;
  std::vector<PeOutboxes> out_;
};

// Flushes every channel's partial batches of PE pe when none of them has a batch waiting for
// pe: a PE runs dry only when nothing more will be handled on it, and flushing earlier would
// send small batches. Call at the end of every task and handler of a batched stage.
template <class... Channels>
void flushIfDry(Pe& pe, Channels&... channels) {
  if ((channels.pending(pe.id()) || ...)) return;
  (channels.flush(pe), ...);
}

}  // namespace pr::par
