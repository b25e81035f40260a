#include "io/specimen.hpp"

#include "io/json_input.hpp"

#include <bit>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <type_traits>

namespace rocklab {

static_assert(std::endian::native == std::endian::little, "specimen files are little-endian");

/// Appends fields to a byte buffer.
struct ArchiveWriter {
  std::string bytes;
  static constexpr bool reading = false;
  template <class T>
  std::enable_if_t<std::is_arithmetic_v<T> || std::is_enum_v<T>> operator()(const T& v) {
    const char* p = reinterpret_cast<const char*>(&v);
    bytes.append(p, sizeof(T));
  }
  void operator()(const Vec3& v) {
    for (int k = 0; k < 3; ++k)
      (*this)(v[k]);
  }
  void operator()(const std::string& s) {
    (*this)(static_cast<std::uint64_t>(s.size()));
    bytes.append(s);
  }
  template <class T, class F> void vec(const std::vector<T>& v, F&& item) {
    (*this)(static_cast<std::uint64_t>(v.size()));
    for (const T& x : v)
      item(const_cast<T&>(x));
  }
};

/// Reads fields back from a byte buffer, failing cleanly on truncation.
struct ArchiveReader {
  const std::string& bytes;
  std::size_t pos = 0;
  std::string file;
  static constexpr bool reading = true;
  void need(std::size_t n) {
    if (pos + n > bytes.size())
      throw InputError(file + ": truncated or corrupt specimen body");
  }
  template <class T>
  std::enable_if_t<std::is_arithmetic_v<T> || std::is_enum_v<T>> operator()(T& v) {
    need(sizeof(T));
    std::memcpy(&v, bytes.data() + pos, sizeof(T));
    pos += sizeof(T);
  }
  void operator()(Vec3& v) {
    for (int k = 0; k < 3; ++k)
      (*this)(v[k]);
  }
  void operator()(std::string& s) {
    std::uint64_t n = 0;
    (*this)(n);
    need(n);
    s.assign(bytes.data() + pos, n);
    pos += n;
  }
  template <class T, class F> void vec(std::vector<T>& v, F&& item) {
    std::uint64_t n = 0;
    (*this)(n);
    if (n > bytes.size()) // every item takes at least a byte
      throw InputError(file + ": corrupt specimen body (impossible element count)");
    v.resize(n);
    for (T& x : v)
      item(x);
  }
};

namespace {

template <class A> void io(A& a, LinearProps& p) {
  a(p.kn), a(p.ks), a(p.fric), a(p.rgap), a(p.lin_mode), a(p.dp_nratio), a(p.dp_sratio),
      a(p.dp_mode), a(p.emod), a(p.kratio), a(p.user_area);
}
template <class A> void io(A& a, PBondProps& p) {
  io(a, p.linear);
  a(p.pb_rmul), a(p.pb_kn), a(p.pb_ks), a(p.pb_mcf), a(p.pb_ten), a(p.pb_coh), a(p.pb_fa),
      a(p.pb_emod), a(p.pb_kratio), a(p.bond), a(p.bond_gap_lo), a(p.bond_gap_hi);
}
template <class A> void io(A& a, FlatJointProps& p) {
  a(p.fj_Nr), a(p.fj_Nal), a(p.fj_rmul), a(p.fj_gap0), a(p.fj_kn), a(p.fj_ks), a(p.fj_fric),
      a(p.fj_ten), a(p.fj_coh), a(p.fj_fa), a(p.fj_emod), a(p.fj_kratio), a(p.bond), a(p.fj_exact);
}
template <class A> void io(A& a, SmoothJointProps& p) {
  a(p.sj_kn), a(p.sj_ks), a(p.sj_fric), a(p.sj_da), a(p.sj_ten), a(p.sj_coh), a(p.sj_fa),
      a(p.sj_rmul), a(p.sj_large), a(p.dip), a(p.ddir), a(p.use_normal), a(p.normal), a(p.bond),
      a(p.bond_gap_lo), a(p.bond_gap_hi);
}
template <class A> void io(A& a, HysteresisProps& p) {
  a(p.hys_knm), a(p.hys_dampn), a(p.hys_ks), a(p.hys_fric), a(p.hys_tenf), a(p.hys_shearf);
}
template <class A> void io(A& a, PowerPlasticProps& p) {
  a(p.pp_kn), a(p.pp_ks), a(p.pp_fric), a(p.pp_T), a(p.pp_b);
}
template <class A> void io(A& a, HysteresisContact& c) {
  a(c.k_load), a(c.k_unload), a(c.ks), a(c.fric), a(c.Fn), a(c.Fss), a(c.Fst), a(c.W_normal),
      a(c.E_hys), a(c.E_slip), a(c.slip), a(c.tenf), a(c.shearf), a(c.state);
}
template <class A> void io(A& a, PowerPlasticContact& c) {
  a(c.kn), a(c.ks), a(c.fric), a(c.T), a(c.b), a(c.x_max), a(c.F_max), a(c.x), a(c.Fn), a(c.Fss),
      a(c.Fst), a(c.W_normal), a(c.E_plastic), a(c.E_slip), a(c.slip);
}
template <class A> void io(A& a, ContactBondProps& p) {
  io(a, p.linear);
  a(p.cb_tenf), a(p.cb_shearf), a(p.bond), a(p.bond_gap_lo), a(p.bond_gap_hi);
}
template <class A> void io(A& a, ModelProps& p) {
  std::uint8_t index = static_cast<std::uint8_t>(p.index());
  a(index);
  if constexpr (A::reading) {
    switch (index) {
    case 0:
      p = LinearProps{};
      break;
    case 1:
      p = PBondProps{};
      break;
    case 2:
      p = FlatJointProps{};
      break;
    case 3:
      p = SmoothJointProps{};
      break;
    case 4:
      p = HysteresisProps{};
      break;
    case 5:
      p = PowerPlasticProps{};
      break;
    case 6:
      p = ContactBondProps{};
      break;
    default:
      throw InputError("corrupt specimen body (unknown contact model)");
    }
  }
  std::visit([&](auto& v) { io(a, v); }, p);
}
template <class A> void io(A& a, LinearParams& p) {
  a(p.kn), a(p.ks), a(p.fric), a(p.rgap), a(p.dp_nratio), a(p.dp_sratio), a(p.lin_mode),
      a(p.dp_mode);
}
template <class A> void io(A& a, LinearState& s) {
  a(s.Fn), a(s.Fss), a(s.Fst), a(s.E_slip), a(s.E_dashpot), a(s.slip);
}
template <class A> void io(A& a, LinearContact& c) {
  io(a, c.p), io(a, c.s);
}
template <class A> void io(A& a, ContactBondContact& c) {
  io(a, c.lin);
  a(c.tenf), a(c.shearf), a(c.state);
}
template <class A> void io(A& a, PBondContact& c) {
  io(a, c.lp), io(a, c.ls);
  a(c.p.rmul), a(c.p.kn), a(c.p.ks), a(c.p.mcf), a(c.p.ten), a(c.p.coh), a(c.p.tan_fa);
  a(c.s.Fn), a(c.s.Fss), a(c.s.Fst), a(c.s.Mt), a(c.s.Mbs), a(c.s.Mbt), a(c.s.gs), a(c.s.sigma),
      a(c.s.tau), a(c.s.R), a(c.s.A), a(c.s.I), a(c.s.J), a(c.s.state);
}
template <class A> void io(A& a, FlatJointContact& c) {
  a(c.kn), a(c.ks), a(c.fric), a(c.ten), a(c.coh), a(c.tan_fa), a(c.rmul), a(c.gap0);
  int dim = c.geo ? c.geo->dim : 3, nr = c.geo ? c.geo->Nr : 1, nal = c.geo ? c.geo->Nal : 3;
  a(dim), a(nr), a(nal);
  if constexpr (A::reading) {
    if ((dim != 2 && dim != 3) || nr < 1 || nal < 1 || nr > 1000 || nal > 1000)
      throw InputError("corrupt specimen body (flat-joint discretisation)");
    c.geo = &flat_joint_geometry(dim, nr, nal);
  }
  a(c.elem), a(c.n_elem), a(c.exact), a(c.fixed), a(c.mtype), a(c.R), a(c.gs), a(c.dss), a(c.dst),
      a(c.tbs), a(c.tbt);
}
template <class A> void io(A& a, FlatJointElement& e) {
  a(e.Fn), a(e.Fss), a(e.Fst), a(e.Mbs), a(e.Mbt), a(e.Mt), a(e.E_slip), a(e.B), a(e.slip);
}
template <class A> void io(A& a, SmoothJointContact& c) {
  a(c.kn), a(c.ks), a(c.fric), a(c.tan_da), a(c.ten), a(c.coh), a(c.tan_fa), a(c.rmul), a(c.large),
      a(c.nj), a(c.A), a(c.un), a(c.us), a(c.gj), a(c.Fn), a(c.Fs), a(c.E_slip), a(c.state),
      a(c.slip);
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
  a(e.kinetic_translational), a(e.kinetic_rotational), a(e.strain), a(e.bond_strain),
      a(e.body_work), a(e.gravity_work), a(e.boundary_work), a(e.local_damping), a(e.slip),
      a(e.dashpot), a(e.plastic), a(e.bond_break), a(e.initial_total);
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
  each(a, batches_.linear), each(a, batches_.pbond), each(a, batches_.flatjoint),
      each(a, batches_.fj_elements), each(a, batches_.smoothjoint), each(a, batches_.hysteresis),
      each(a, batches_.powerplastic), each(a, batches_.contactbond);
  a(time_), a(dt_), a(margin_), a(max_ball_disp_), a(wall_disp_), a(max_speed_), a(dt_stiffness_),
      a(step_), a(initialized_);
  io(a, ledger_);
  io(a, retired_);
  each(a, group_retired_), each(a, broken_);
  if constexpr (A::reading) {
    if (outputs_.size() != contacts_.size())
      throw InputError("corrupt specimen body (contact arrays of different lengths)");
    for (const Contact& c : contacts_)
      if (c.end1 < 0 || static_cast<std::size_t>(c.end1) >= n ||
          (c.kind == ContactKind::BallBall &&
           (c.end2 < 0 || static_cast<std::size_t>(c.end2) >= n)))
        throw InputError("corrupt specimen body (contact end out of range)");
    for (std::size_t k = 0; k < clumps.size(); ++k)
      for (std::int32_t p : clumps[k].pebbles)
        if (p < 0 || static_cast<std::size_t>(p) >= n ||
            balls.clump[static_cast<std::size_t>(p)] != static_cast<std::int32_t>(k))
          throw InputError("corrupt specimen body (clump pebble out of range)");
    rebuild_adjacency(); // derived data, exactly as detection builds it
  }
}

template void Model::serialize<ArchiveWriter>(ArchiveWriter&);
template void Model::serialize<ArchiveReader>(ArchiveReader&);

void save_model(const Model& m, const std::string& path, const nlohmann::json& meta) {
  ArchiveWriter w;
  const_cast<Model&>(m).serialize(w); // the writer only reads
  nlohmann::json header{{"format", "rocklab-specimen"},
                        {"version", kSpecimenVersion},
                        {"units", "SI"},
                        {"dimension", m.settings.dim},
                        {"balls", m.balls.size()},
                        {"contacts", m.contacts().size()},
                        {"body_bytes", w.bytes.size()},
                        {"meta", meta}};
  const std::filesystem::path target(path);
  const std::filesystem::path tmp = target.string() + ".partial";
  {
    std::ofstream out(tmp, std::ios::binary);
    if (!out)
      throw std::runtime_error(path + ": cannot open for writing");
    out << header.dump() << '\n';
    out.write(w.bytes.data(), static_cast<std::streamsize>(w.bytes.size()));
    out.close();
    if (!out) {
      std::error_code ec;
      std::filesystem::remove(tmp, ec);
      throw std::runtime_error(path + ": write failed (disk full?)");
    }
  }
  std::filesystem::rename(tmp, target);
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
  if (!header.is_object() || header.value("format", "") != "rocklab-specimen")
    throw InputError(path + ": not a rocklab specimen file (format is not \"rocklab-specimen\")");
  const int version = header.value("version", 0);
  if (version != kSpecimenVersion)
    throw InputError(path + ": key 'version': value " + std::to_string(version) +
                     " is not supported (this rocklab reads version " +
                     std::to_string(kSpecimenVersion) + ")");
  const std::string body((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (body.size() != header.value("body_bytes", static_cast<std::size_t>(0)))
    throw InputError(path + ": truncated specimen file (body has " + std::to_string(body.size()) +
                     " bytes, header says " + header["body_bytes"].dump() + ")");
  ArchiveReader r{body, 0, path};
  auto m = std::make_unique<Model>();
  try {
    m->serialize(r);
  } catch (const InputError& e) {
    const std::string what = e.what();
    throw InputError(what.rfind(path, 0) == 0 ? what : path + ": " + what);
  }
  if (r.pos != body.size())
    throw InputError(path + ": corrupt specimen body (trailing bytes)");
  if (meta)
    *meta = header.value("meta", nlohmann::json::object());
  return m;
}

} // namespace rocklab
