// The contact list rebuilt in place. A detection (merge_candidates) and the editing calls that
// drop contacts (compact_contacts) decide which contacts stay and which are new; the list, its
// outputs and every model's batch then move to their new places inside their own arrays: kept
// contacts to the front, then everything to its final place from the back. A second copy of the
// list is never made (it held a third of a 10k-grain flat-jointed run's memory).
#include "core/model.hpp"

#include <cassert>
#include <stdexcept>
#include <string>

namespace rocklab {

bool Model::batches_packed() const {
  // Each model's slots count up in contact order from 0 and its batch holds nothing else (no
  // data left behind by replace_contact_model); a pool's parts lie in slot order without holes.
  std::array<std::uint32_t, kModelCount> next{};
  for (const Contact& c : contacts_)
    if (c.slot != next[static_cast<std::size_t>(c.model)]++)
      return false;
  bool packed = true;
  for_each_model([&]<class M>() {
    const Batch<M>& b = batches_.of<M>();
    packed = packed && b.contacts.size() == next[static_cast<std::size_t>(model_kind<M>)];
    if constexpr (HasPool<M>)
      packed = packed && b.pool.packed(b.contacts);
  });
  return packed;
}

void Model::pack_batches() {
  // Copies every model's data once, into contact order (rare: after contact models were replaced
  // or a specimen whose batches were not packed was read).
  ModelBatches packed;
  packed.reserve_like(batches_);
  for (Contact& c : contacts_)
    c.slot = move_contact_data(packed, batches_, c.model, c.slot);
  std::swap(batches_, packed);
}

namespace {

/// Move the kept contacts' data to the front of one model's batch, in contact order; their
/// slots then index the packed front. Returns the number kept.
template <class M>
std::size_t pack_kept(Batch<M>& b, std::vector<Contact>& list,
                      const std::vector<std::uint8_t>& added) {
  constexpr ModelKind kind = model_kind<M>;
  std::size_t w = 0, pool_at = 0;
  for (std::size_t f = 0; f < list.size(); ++f) {
    Contact& c = list[f];
    if (c.model != kind || added[f])
      continue;
    assert(c.slot >= w && "kept contacts' slots count up");
    if (c.slot != w)
      b.contacts[w] = b.contacts[c.slot];
    if constexpr (HasPool<M>)
      pool_at = b.pool.pack_to(b.contacts[w], pool_at);
    c.slot = static_cast<std::uint32_t>(w++);
  }
  return w;
}

/// Place every contact's data of one model at its final slot, from the back: the added
/// contacts' from `from`, the kept ones' from the packed front.
template <class M>
void place_all(Batch<M>& b, const Batch<M>& from, std::size_t kept, std::vector<Contact>& list,
               const std::vector<std::uint8_t>& added) {
  constexpr ModelKind kind = model_kind<M>;
  std::size_t end = kept + from.contacts.size();
  reserve_with_slack(b.contacts, end);
  b.contacts.resize(end);
  std::size_t pool_end = 0;
  if constexpr (HasPool<M>) {
    pool_end = kept == 0 ? 0 : b.contacts[kept - 1].elem + b.contacts[kept - 1].n_elem;
    pool_end += from.pool.size();
    reserve_with_slack(b.pool.all, pool_end);
    b.pool.all.resize(pool_end);
  }
  for (std::size_t f = list.size(); f-- > 0;) {
    Contact& c = list[f];
    if (c.model != kind)
      continue;
    --end;
    if (added[f]) {
      b.contacts[end] = from.contacts[c.slot];
      if constexpr (HasPool<M>)
        pool_end = b.pool.copy_before(from.pool, b.contacts[end], pool_end);
    } else {
      assert(c.slot <= end && "kept contacts move toward the back");
      if (c.slot != end)
        b.contacts[end] = b.contacts[c.slot];
      if constexpr (HasPool<M>)
        pool_end = b.pool.place_before(b.contacts[end], pool_end);
    }
    c.slot = static_cast<std::uint32_t>(end);
  }
  if (end != 0 || pool_end != 0) // cheap, and a wrong layout would corrupt contacts silently
    throw std::logic_error("contact list rebuilt with " + std::to_string(end) + " slots and " +
                           std::to_string(pool_end) + " pool items of " + std::string(M::name) +
                           " unplaced");
}

} // namespace

void Model::rebuild_contacts() {
  // keep_[i]: contact i stays; order_[f]: 1 when the f-th contact of the new list is the next of
  // added_contacts_ (whose slots index added_batches_), 0 when it is the next kept one.
  assert(keep_.size() == contacts_.size() && "a keep flag per contact");
  if (!batches_packed())
    pack_batches();
  std::size_t kept = 0;
  for (std::size_t i = 0; i < contacts_.size(); ++i)
    if (keep_[i]) {
      if (kept != i) {
        contacts_[kept] = contacts_[i];
        outputs_[kept] = outputs_[i];
      }
      ++kept;
    }
  const std::size_t total = order_.size();
  assert(total == kept + added_contacts_.size() && "every contact has its place");
  reserve_with_slack(contacts_, total);
  reserve_with_slack(outputs_, total);
  contacts_.resize(total);
  outputs_.resize(total);
  for (std::size_t f = total, a = kept, n = added_contacts_.size(); f-- > 0;) {
    if (order_[f]) {
      contacts_[f] = added_contacts_[--n];
      outputs_[f] = added_outputs_[n];
    } else if (--a != f) {
      contacts_[f] = contacts_[a];
      outputs_[f] = outputs_[a];
    }
  }
  for_each_model([&]<class M>() {
    Batch<M>& b = batches_.of<M>();
    const Batch<M>& from = added_batches_.of<M>();
    if (b.contacts.empty() && from.contacts.empty())
      return;
    place_all(b, from, pack_kept(b, contacts_, order_), contacts_, order_);
  });
  added_contacts_.clear();
  added_outputs_.clear();
  added_batches_.clear();
}

void Model::compact_contacts(const std::function<bool(Contact&)>& keep) {
  // Keep (and let `keep` renumber) some contacts in their order; the dropped ones retire their
  // dissipation.
  keep_.assign(contacts_.size(), 0);
  order_.clear();
  for (std::size_t ci = 0; ci < contacts_.size(); ++ci) {
    Contact c = contacts_[ci];
    if (!keep(c)) {
      retire_dissipation(contacts_[ci]);
      continue;
    }
    c.key = contact_key(c.kind, c.end1, c.end2);
    contacts_[ci] = c;
    keep_[ci] = 1;
    order_.push_back(0);
  }
  rebuild_contacts();
}

void Model::release_scratch() {
  std::vector<Contact>().swap(added_contacts_);
  std::vector<ContactOutput>().swap(added_outputs_);
  added_batches_ = ModelBatches{};
  std::vector<std::uint8_t>().swap(keep_);
  std::vector<std::uint8_t>().swap(order_);
  std::vector<std::uint64_t>().swap(candidate_keys_);
  for (auto& keys : thread_keys_)
    std::vector<std::uint64_t>().swap(keys);
}

} // namespace rocklab
