// Channel<T>: typed message passing between PEs (one mailbox per PE), the only path for a PDI
// or result to move between PEs. Every send is counted at the sender — messages and bytes per
// sender->receiver pair and per stage, as its encoding's size (wire.h) — so the counts are the communication volume
// (shared/DESIGN.md rule 1). With a handler the channel drives a message-driven phase: the
// runtime runs the handler on the receiving PE and detects termination (termination.h).
#pragma once

#include <chrono>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "common/parallel/runtime.h"
#include "common/parallel/wire.h"
#include "common/util/error.h"

namespace pr::par {

template <class T>
class Channel : public ChannelBase {
 public:
  using Handler = std::function<void(Pe&, T&&)>;

  // Without a handler, messages wait in the mailboxes until the receiver takes them
  // (tryReceive inside a later task, or drain between stages).
  Channel(Runtime& runtime, std::string name, MessageKind kind, Handler handler = {})
      : ChannelBase(std::move(name), kind), runtime_(runtime), handler_(std::move(handler)) {
    for (int p = 0; p < runtime_.pes(); ++p) boxes_.push_back(std::make_unique<Mailbox>());  // only local ones used
    runtime_.attach(this, bool(handler_));
  }
  ~Channel() override { runtime_.detach(this); }
  Channel(const Channel&) = delete;
  Channel& operator=(const Channel&) = delete;

  // Called by PE `from` inside a task or handler: counted as its encoding's size (wire.h).
  void send(Pe& from, int to, T message) {
    const std::size_t bytes = Wire<T>::size(message);
    sendDeclared(from, to, std::move(message), bytes);
  }

  // The same as send, with the encoding's size already known (summed as the message was built).
  void sendEncoded(Pe& from, int to, T message, std::size_t encodedBytes) {
    PR_DCHECK(encodedBytes == Wire<T>::size(message), "Channel '" + name() + "': stated size is not the encoding's");
    sendDeclared(from, to, std::move(message), encodedBytes);
  }

  // A message whose counted size the sender states instead of its encoding: the data manager's
  // requests and items (counted as the simulator charges them: 16 bytes a request, an item's
  // encoding without the reply's header) and gatherToRoot's lists (their items).
  void sendDeclared(Pe& from, int to, T message, std::size_t bytes) {
    PR_CHECK(to >= 0 && to < runtime_.pes(), "Channel '" + name() + "': destination PE out of range");
    const SendReceiveTimer timer(from);
    runtime_.countMessage(from.id(), to, bytes);
    const bool local = runtime_.isLocal(to);
    if (from.id() != to) countSent(bytes, !local);
    if (!local) return sendToRank(from.id(), to, message, bytes);
    if (handler_) runtime_.outstanding().add();  // before the receiver can see it
    enqueue(to, std::move(message));
  }
  // One copy to every other PE, counted once per receiving PE.
  void broadcast(Pe& from, const T& message) {
    for (int p = 0; p < runtime_.pes(); ++p)
      if (p != from.id()) send(from, p, message);
  }

  // Inside a task on PE `me`: takes one waiting message, if any.
  bool tryReceive(Pe& me, T& out) {
    PR_CHECK(!handler_, "Channel '" + name() + "' has a handler; its messages are delivered to it");
    const SendReceiveTimer timer(me);
    std::optional<T> message;
    if (!pop(me.id(), message)) return false;
    out = std::move(*message);
    return true;
  }

  // Between stages, on the controlling thread: every message waiting for pe, in arrival order.
  std::vector<T> drain(int pe) {
    std::lock_guard lock(boxes_[pe]->mutex);
    std::vector<T> all(std::make_move_iterator(boxes_[pe]->queue.begin()),
                       std::make_move_iterator(boxes_[pe]->queue.end()));
    boxes_[pe]->queue.clear();
    boxes_[pe]->size.store(0, std::memory_order_release);
    return all;
  }

  // For a message type whose decoding needs what only the receiver has (the scene an item's
  // BVH is tested against): how a message from another rank is decoded, instead of Wire<T>.
  // Set before the stage whose messages need it.
  void decodeWith(std::function<T(WireReader&)> decoder) { decoder_ = std::move(decoder); }

  bool pending(int pe) const override { return boxes_[pe]->size.load(std::memory_order_acquire) > 0; }

  bool handleOne(Pe& pe) override {
    std::optional<T> message;
    {
      const SendReceiveTimer timer(pe);
      if (!pop(pe.id(), message)) return false;
    }
    handler_(pe, std::move(*message));
    return true;
  }

  void deliver(int from, int to, std::span<const std::byte> encoding, std::size_t counted) override {
    if constexpr (HasWire<T>) {
      T message = decoder_ ? decodeWithDecoder(encoding) : decodeMessage<T>(encoding);
      (void)from;
      runtime_.countReceived(to, counted);
      if (handler_) runtime_.outstanding().add();
      enqueue(to, std::move(message));
    } else {
      throw std::logic_error("Channel '" + name() + "': a message without an encoding arrived from another rank");
    }
  }

 private:
  struct Mailbox {
    std::mutex mutex;
    std::deque<T> queue;
    std::atomic<std::size_t> size{0};  // lets an idle PE poll without taking the lock
  };

  void enqueue(int to, T&& message) {
    {
      std::lock_guard lock(boxes_[to]->mutex);
      boxes_[to]->queue.push_back(std::move(message));
      boxes_[to]->size.store(boxes_[to]->queue.size(), std::memory_order_release);
    }
    runtime_.ring(to);
  }

  // To a PE on another rank: the message's encoding, behind room for the runtime's header.
  void sendToRank(int from, int to, const T& message, std::size_t counted) {
    if constexpr (HasWire<T>) {
      Bytes framed = runtime_.sendStorage(Runtime::kFrameBytes + Wire<T>::size(message));
      framed.resize(Runtime::kFrameBytes);
      WireWriter w(framed);
      Wire<T>::encode(message, w);
      runtime_.sendToRank(*this, from, to, std::move(framed), counted);
    } else {
      throw std::logic_error("Channel '" + name() + "': its messages have no encoding (Wire) and cannot leave a rank");
    }
  }

  T decodeWithDecoder(std::span<const std::byte> encoding) const {
    WireReader r(encoding);
    T message = decoder_(r);
    if (r.remaining() != 0) throw WireError(std::to_string(r.remaining()) + " bytes left over after a message");
    return message;
  }

  bool pop(int pe, std::optional<T>& out) {
    Mailbox& box = *boxes_[pe];
    if (box.size.load(std::memory_order_acquire) == 0) return false;
    std::lock_guard lock(box.mutex);
    if (box.queue.empty()) return false;
    out.emplace(std::move(box.queue.front()));
    box.queue.pop_front();
    box.size.store(box.queue.size(), std::memory_order_release);
    return true;
  }

  Runtime& runtime_;
  Handler handler_;
  std::function<T(WireReader&)> decoder_;
  std::vector<std::unique_ptr<Mailbox>> boxes_;
};

}  // namespace pr::par
