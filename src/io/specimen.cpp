#include "io/specimen.hpp"

#include "io/json_input.hpp"
#include "io/output_dir.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string_view>
#include <type_traits>

namespace rocklab {

static_assert(std::endian::native == std::endian::little, "specimen files are little-endian");

/// Bodies are written, hashed and read a chunk of this many bytes at a time.
constexpr std::size_t kArchiveChunk = std::size_t{1} << 20;

/// Writes fields a chunk of about 1 MiB at a time to `out`, or without `out` only counts and
/// hashes them (the header line before the body gives its size and hash).
struct ArchiveWriter {
  std::ostream* out = nullptr;
  std::string bytes; ///< the pending chunk
  std::uint64_t size = 0, hash = fnv1a64("");
  static constexpr bool reading = false;
  static constexpr std::uint64_t version = kSpecimenVersion;
  void put(const char* p, std::size_t n) {
    bytes.append(p, n);
    size += n;
    if (bytes.size() >= kArchiveChunk)
      flush();
  }
  void flush() {
    if (out)
      out->write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    else
      hash = fnv1a64(bytes, hash);
    bytes.clear();
  }
  template <class T>
  std::enable_if_t<std::is_arithmetic_v<T> || std::is_enum_v<T>> operator()(const T& v) {
    put(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  void operator()(const Vec3& v) {
    for (int k = 0; k < 3; ++k)
      (*this)(v[k]);
  }
  void operator()(const std::string& s) {
    (*this)(static_cast<std::uint64_t>(s.size()));
    put(s.data(), s.size());
  }
  template <class T, class F> void vec(const std::vector<T>& v, F&& item) {
    (*this)(static_cast<std::uint64_t>(v.size()));
    for (const T& x : v)
      item(const_cast<T&>(x));
  }
};

/// Reads fields back from the body in a file, a chunk of about 1 MiB at a time (the body of a
/// 10k-grain specimen read whole took 31 MB beside the model made from it), failing cleanly on
/// truncation: `size` is the body's length, checked before any field is read.
struct ArchiveReader {
  std::istream& in;
  std::uint64_t size = 0;
  std::string file;
  std::uint64_t version = kSpecimenVersion; ///< of the file: older ones lack the newer fields
  std::uint64_t pos = 0;                    ///< bytes of the body read
  std::string chunk;
  std::size_t at = 0; ///< the next byte of `chunk`
  static constexpr bool reading = true;

  std::uint64_t remaining() const { return size - pos; }
  void need(std::uint64_t n) {
    if (n > remaining()) // pos <= size: no wrap-around for a length near 2^64
      throw InputError(file + ": truncated or corrupt specimen body");
  }
  /// Copy the next n bytes (n <= remaining()) to p.
  void take(char* p, std::size_t n) {
    need(n);
    pos += n;
    while (n > 0) {
      if (at == chunk.size()) {
        chunk.resize(kArchiveChunk);
        in.read(chunk.data(), static_cast<std::streamsize>(kArchiveChunk));
        chunk.resize(static_cast<std::size_t>(in.gcount()));
        at = 0;
        if (chunk.empty())
          throw InputError(file + ": truncated specimen file (the body ended while read)");
      }
      const std::size_t k = std::min(n, chunk.size() - at);
      std::memcpy(p, chunk.data() + at, k);
      at += k, p += k, n -= k;
    }
  }
  template <class T>
  std::enable_if_t<std::is_arithmetic_v<T> || std::is_enum_v<T>> operator()(T& v) {
    take(reinterpret_cast<char*>(&v), sizeof(T));
  }
  void operator()(Vec3& v) {
    for (int k = 0; k < 3; ++k)
      (*this)(v[k]);
  }
  // Flags and enumerations are bytes with few valid values: a byte read into a bool that is not
  // 0 or 1 is undefined behaviour, an unknown enumerator selects nothing.
  std::uint8_t byte_at_most(std::uint8_t hi, const char* what) {
    std::uint8_t b = 0;
    (*this)(b);
    if (b > hi)
      throw InputError(file + ": corrupt specimen body (" + what + " holds " + std::to_string(b) +
                       ", at most " + std::to_string(hi) + " allowed)");
    return b;
  }
  void operator()(bool& v) { v = byte_at_most(1, "a flag") != 0; }
  void operator()(BondState& v) { v = static_cast<BondState>(byte_at_most(3, "a bond state")); }
  void operator()(ContactKind& v) {
    v = static_cast<ContactKind>(byte_at_most(1, "a contact kind"));
  }
  void operator()(ModelKind& v) {
    v = static_cast<ModelKind>(byte_at_most(kModelCount - 1, "a contact model"));
  }
  void operator()(std::string& s) {
    std::uint64_t n = 0;
    (*this)(n);
    need(n);
    s.resize(n);
    take(s.data(), n);
  }
  template <class T, class F> void vec(std::vector<T>& v, F&& item) {
    std::uint64_t n = 0;
    (*this)(n);
    if (n > remaining()) // every item takes at least a byte
      throw InputError(file + ": corrupt specimen body (impossible element count)");
    v.resize(n);
    for (T& x : v)
      item(x);
  }
};

namespace {

template <class A> void io(A& a, ModelProps& p) {
  std::uint8_t index = static_cast<std::uint8_t>(p.index());
  a(index);
  if constexpr (A::reading) {
    if (index >= kModelCount)
      throw InputError("corrupt specimen body (unknown contact model)");
    visit_model(static_cast<ModelKind>(index), [&]<class M>() { p = typename M::Props{}; });
  }
  visit_model(static_cast<ModelKind>(index),
              [&]<class M>() { M::io(a, std::get<typename M::Props>(p)); });
}
template <class A> void io(A& a, Contact& c) {
  a(c.key), a(c.end1), a(c.end2), a(c.facet), a(c.kind), a(c.model), a(c.slot), a(c.initialized),
      a(c.n), a(c.s), a(c.t), a(c.gap);
}
template <class A> void io(A& a, ContactOutput& o) {
  a(o.xc), a(o.force), a(o.moment), a(o.stiff.k_tran), a(o.stiff.k_shear), a(o.stiff.k_rot);
}
template <class A> void io(A& a, Wall& w) {
  a(w.name);
  a.vec(w.facets, [&](Facet& f) {
    a(f.nv);
    for (auto& v : f.v)
      a(v);
  });
  a(w.cylinder_radius), a(w.half_height);
  a(w.center), a(w.velocity), a(w.spin), a(w.radial_velocity), a(w.axis), a(w.radial_force),
      a(w.force), a(w.moment), a(w.lo), a(w.hi);
}
template <class A> void io(A& a, ModelRule& r) {
  a(r.ball_facet), a(r.group1), a(r.group2), a(r.wall), a(r.inherit);
  io(a, r.props);
}
template <class A> void io(A& a, SurfaceProps& p) {
  a(p.kn), a(p.ks), a(p.fric), a(p.sj_kn), a(p.sj_ks), a(p.sj_fric);
}
template <class A> void io(A& a, EnergyLedger& e) {
  e.terms([&](double& x) { a(x); });
}
template <class A> void io(A& a, ContactEnergy& e) {
  a(e.strain), a(e.bond_strain), a(e.slip), a(e.dashpot), a(e.plastic);
}
template <class A, class T> void each(A& a, std::vector<T>& v) {
  a.vec(v, [&](T& x) {
    if constexpr (std::is_arithmetic_v<T> || std::is_same_v<T, Vec3>)
      a(x);
    else
      io(a, x);
  });
}

} // namespace

template <class A> void Model::serialize(A& a) {
  a(settings.dim), a(settings.gravity), a(settings.local_damping), a(settings.timestep),
      a(settings.timestep_safety), a(settings.margin), a(settings.overlap_check),
      a(settings.slip_events);
  each(a, balls.pos), each(a, balls.vel), each(a, balls.spin), each(a, balls.force),
      each(a, balls.moment), each(a, balls.applied_force), each(a, balls.applied_moment),
      each(a, balls.disp), each(a, balls.radius), each(a, balls.mass), each(a, balls.inertia),
      each(a, balls.density), each(a, balls.fixity), each(a, balls.group), each(a, balls.id);
  each(a, balls.clump), each(a, balls.body_work), each(a, balls.gravity_work),
      each(a, balls.damping_work);
  a.vec(clumps, [&](Clump& c) {
    a(c.id), a(c.group);
    each(a, c.pebbles), each(a, c.offset);
    a(c.mass), a(c.inertia), a(c.pos), a(c.vel), a(c.L), a(c.spin), a(c.q.w()), a(c.q.x()),
        a(c.q.y()), a(c.q.z()), a(c.applied_force), a(c.applied_moment), a(c.body_work),
        a(c.gravity_work), a(c.local_damping);
  });
  const std::size_t n = balls.size();
  for (std::size_t len :
       {balls.vel.size(), balls.spin.size(), balls.force.size(), balls.radius.size(),
        balls.mass.size(), balls.fixity.size(), balls.group.size(), balls.id.size(),
        balls.disp.size(), balls.clump.size(), balls.body_work.size(), balls.damping_work.size(),
        balls.gravity_work.size()})
    if (len != n)
      throw InputError("corrupt specimen body (ball arrays of different lengths)");
  a.vec(walls, [&](Wall& w) { io(a, w); });
  a.vec(group_names, [&](std::string& s) { a(s); });
  each(a, rules), each(a, surface);
  each(a, contacts_), each(a, outputs_);
  for_each_model([&]<class M>() {
    Batch<M>& b = batches_.of<M>();
    a.vec(b.contacts, [&](typename M::Contact& c) { M::io(a, c); });
    if constexpr (HasPool<M>)
      M::io(a, b.pool);
  });
  a(time_), a(dt_), a(margin_), a(max_ball_disp_), a(wall_disp_), a(max_speed_), a(dt_stiffness_),
      a(step_), a(initialized_);
  io(a, ledger_);
  io(a, retired_);
  each(a, group_retired_), each(a, broken_);
  if (a.version >= 7) {
    bool track = balls.tracks_orientation();
    a(track);
    if constexpr (A::reading)
      balls.track_orientation(track);
    if (track)
      a.vec(balls.orient, [&](Eigen::Quaterniond& q) { a(q.w()), a(q.x()), a(q.y()), a(q.z()); });
  }
  if (a.version >= 8) // density scaling of a checkpointed quasi-static test (empty: off)
    each(a, mass_scale_), each(a, inertia_scale_);
  if constexpr (A::reading) {
    if (outputs_.size() != contacts_.size())
      throw InputError("corrupt specimen body (contact arrays of different lengths)");
    if (const std::string bad = check_loaded(); !bad.empty())
      throw InputError("corrupt specimen body (" + bad + ")");
    rebuild_adjacency(); // derived data, exactly as detection builds it
  }
}

std::string Model::check_loaded() const {
  const std::size_t n = balls.size();
  const auto in = [](std::int64_t i, std::size_t size) {
    return i >= 0 && static_cast<std::size_t>(i) < size;
  };
  for (std::size_t i = 0; i < n; ++i) {
    if (!balls.pos[i].allFinite() || !balls.vel[i].allFinite() || !balls.spin[i].allFinite())
      return "ball " + std::to_string(i) + ": a position or velocity is not finite";
    if (!(balls.radius[i] > 0 && std::isfinite(balls.radius[i])) || !(balls.mass[i] > 0))
      return "ball " + std::to_string(i) + ": radius or mass not positive";
    if (!in(balls.group[i], group_names.size()))
      return "ball " + std::to_string(i) + ": group index out of range";
    if (balls.clump[i] != -1 && !in(balls.clump[i], clumps.size()))
      return "ball " + std::to_string(i) + ": clump index out of range";
  }
  if (balls.tracks_orientation()) {
    if (balls.orient.size() != n)
      return "orientations for " + std::to_string(balls.orient.size()) + " of " +
             std::to_string(n) + " balls";
    for (std::size_t i = 0; i < n; ++i)
      if (!(std::abs(balls.orient[i].norm() - 1) < 1e-9))
        return "ball " + std::to_string(i) + ": orientation is not a unit quaternion";
  }
  if (mass_scale_.size() != inertia_scale_.size() ||
      (!mass_scale_.empty() && mass_scale_.size() != n))
    return "density scaling for " + std::to_string(mass_scale_.size()) + " of " +
           std::to_string(n) + " balls";
  for (std::size_t i = 0; i < mass_scale_.size(); ++i)
    if (!(mass_scale_[i] >= 1 && inertia_scale_[i] >= 1 && std::isfinite(mass_scale_[i]) &&
          std::isfinite(inertia_scale_[i])))
      return "ball " + std::to_string(i) + ": a density-scaling factor is not finite and >= 1";
  for (std::size_t k = 0; k < clumps.size(); ++k)
    for (std::int32_t p : clumps[k].pebbles)
      if (!in(p, n) || balls.clump[static_cast<std::size_t>(p)] != static_cast<std::int32_t>(k))
        return "clump " + std::to_string(k) + ": pebble out of range";
  for (const Wall& w : walls)
    for (const Facet& f : w.facets)
      if (f.nv < 2 || f.nv > 3)
        return "wall '" + w.name + "': a facet with " + std::to_string(f.nv) + " vertices";
  std::array<std::size_t, kModelCount> slots{};
  for_each_model([&]<class M>() {
    slots[static_cast<std::size_t>(model_kind<M>)] = batches_.of<M>().contacts.size();
  });
  for (std::size_t k = 0; k < contacts_.size(); ++k) {
    const Contact& c = contacts_[k];
    const bool facet = c.kind == ContactKind::BallFacet;
    if (!in(c.end1, n) || (!facet && !in(c.end2, n)) || (facet && !in(c.end2, walls.size())))
      return "contact " + std::to_string(k) + ": end out of range";
    if (facet && c.facet != -1) {
      const Wall& w = walls[static_cast<std::size_t>(c.end2)];
      // An exact cylinder is one surface: its contacts carry facet 0 (Wall::closest_point).
      if (!in(c.facet, w.is_cylinder() ? std::size_t{1} : w.facets.size()))
        return "contact " + std::to_string(k) + ": facet out of range";
    }
    if (!in(c.slot, slots[static_cast<std::size_t>(c.model)]))
      return "contact " + std::to_string(k) + ": model slot out of range";
    if (c.key != contact_key(c.kind, c.end1, c.end2))
      return "contact " + std::to_string(k) + ": key does not match its ends";
  }
  std::string bad;
  for_each_model([&]<class M>() {
    if constexpr (HasPool<M>) {
      const Batch<M>& b = batches_.of<M>();
      for (std::size_t k = 0; k < b.contacts.size() && bad.empty(); ++k)
        bad = M::check_loaded(b.contacts[k], b.pool);
    }
  });
  return bad;
}

template void Model::serialize<ArchiveWriter>(ArchiveWriter&);
template void Model::serialize<ArchiveReader>(ArchiveReader&);

void save_model(const Model& m, const std::string& path, const nlohmann::json& meta) {
  // Two passes over the model (the writer only reads it): the first counts and hashes the body
  // for the header line, the second streams it to the file. Built whole in a string grown by
  // doubling, a 10k-grain checkpoint's 31 MB body took up to three times that while it was made.
  ArchiveWriter w;
  const_cast<Model&>(m).serialize(w);
  w.flush();
  nlohmann::json header{{"format", "rocklab-specimen"},
                        {"version", kSpecimenVersion},
                        {"units", "SI"},
                        {"dimension", m.settings.dim},
                        {"balls", m.balls.size()},
                        {"contacts", m.contacts().size()},
                        {"body_bytes", w.size},
                        {"body_fnv1a64", hash_hex(w.hash)},
                        {"meta_fnv1a64", text_hash(meta.dump())},
                        {"meta", meta}};
  write_file_atomically(path, [&](std::ostream& out) {
    out << header.dump() << '\n';
    ArchiveWriter body;
    body.out = &out;
    const_cast<Model&>(m).serialize(body);
    body.flush();
  });
}

std::unique_ptr<Model> load_model(const std::string& path, nlohmann::json* meta) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw InputError(path + ": cannot open specimen file (missing or unreadable)");
  std::string line;
  std::getline(in, line);
  nlohmann::json header;
  try {
    header = nlohmann::json::parse(line);
  } catch (const nlohmann::json::exception&) {
    throw InputError(path + ": not a rocklab specimen file (no JSON header line)");
  }
  if (!header.is_object() || !header.contains("format") || header["format"] != "rocklab-specimen")
    throw InputError(path + ": not a rocklab specimen file (format is not \"rocklab-specimen\")");
  const auto header_number = [&](const char* key) {
    if (!header.contains(key) || !header[key].is_number_unsigned())
      throw InputError(path + ": key '" + key +
                       "': " + (header.contains(key) ? "value " + header[key].dump() : "missing") +
                       " (a whole number >= 0 expected in the header line)");
    return header[key].get<std::uint64_t>();
  };
  const std::uint64_t version = header_number("version");
  if (version < 5 || version > static_cast<std::uint64_t>(kSpecimenVersion))
    throw InputError(path + ": key 'version': value " + std::to_string(version) +
                     " is not supported (this rocklab reads versions 5 to " +
                     std::to_string(kSpecimenVersion) + ")");
  const std::uint64_t body_bytes = header_number("body_bytes");
  // The body is read twice, a chunk at a time: for its length and checksum, then for its fields.
  const std::streampos body_start = in.tellg();
  std::uint64_t body_size = 0, hash = fnv1a64("");
  {
    std::string chunk(kArchiveChunk, '\0');
    while (in.read(chunk.data(), static_cast<std::streamsize>(chunk.size())) || in.gcount() > 0) {
      const auto n = static_cast<std::size_t>(in.gcount());
      body_size += n;
      hash = fnv1a64(std::string_view(chunk.data(), n), hash);
    }
  }
  if (body_size != body_bytes)
    throw InputError(path + ": truncated specimen file (body has " + std::to_string(body_size) +
                     " bytes, header says " + std::to_string(body_bytes) + ")");
  if (header.contains("meta") && !header["meta"].is_object() && !header["meta"].is_null())
    throw InputError(path + ": key 'meta': not an object");
  // The checksums first (version 5 files predate them): a changed byte anywhere in the body, or
  // in the metadata (a checkpoint's machine state, hashed as its JSON text), is named as such
  // before any field is read.
  if (version >= 6) {
    const std::string body_hash = hash_hex(hash);
    if (!header.contains("body_fnv1a64") || !header["body_fnv1a64"].is_string())
      throw InputError(path + ": key 'body_fnv1a64': missing (the body's checksum)");
    if (header["body_fnv1a64"].get<std::string>() != body_hash)
      throw InputError(path + ": the body does not match its checksum (key 'body_fnv1a64': " +
                       header["body_fnv1a64"].dump() + ", the body hashes to \"" + body_hash +
                       "\"): the file was changed or damaged after rocklab wrote it");
    const std::string meta_hash = text_hash(header.value("meta", nlohmann::json()).dump());
    if (header.value("meta_fnv1a64", nlohmann::json()) != meta_hash)
      throw InputError(path + ": key 'meta' does not match its checksum (key 'meta_fnv1a64'): "
                              "the file was changed or damaged after rocklab wrote it");
  }
  in.clear();
  in.seekg(body_start);
  if (!in)
    throw InputError(path + ": cannot read the specimen file's body again");
  ArchiveReader r{in, body_bytes, path, version, 0, {}, 0};
  auto m = std::make_unique<Model>();
  try {
    m->serialize(r);
  } catch (const InputError& e) {
    const std::string what = e.what();
    throw InputError(what.rfind(path, 0) == 0 ? what : path + ": " + what);
  }
  if (r.pos != body_bytes)
    throw InputError(path + ": corrupt specimen body (trailing bytes)");
  if (meta)
    *meta = header.value("meta", nlohmann::json::object());
  return m;
}

void save_specimen(const Model& m, const std::string& path, const nlohmann::json& meta,
                   const nlohmann::json& report) {
  const std::string report_file = path + ".report.json";
  write_text_file(report_file + ".partial", report.dump(1) + "\n");
  try {
    save_model(m, path, meta);
  } catch (...) {
    std::remove((report_file + ".partial").c_str());
    throw;
  }
  std::rename((report_file + ".partial").c_str(), report_file.c_str());
}

} // namespace rocklab
