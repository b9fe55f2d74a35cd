#include "edgefem/core/checkpoint.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "simulator/checkpoint_file.hpp"
#include "simulator/checkpoint_stream.hpp"

namespace edgefem {

std::uint64_t fnv1a(std::string_view bytes, std::uint64_t hash) {
    for (const char c : bytes) {
        hash ^= static_cast<unsigned char>(c);
        hash *= 0x100000001b3ull;
    }
    return hash;
}

std::uint64_t mesh_hash(const Mesh& mesh) {
    const std::uint64_t h = fnv1a({reinterpret_cast<const char*>(mesh.X.data()), mesh.X.size() * sizeof(double)});
    return fnv1a({reinterpret_cast<const char*>(mesh.tets.data()), mesh.tets.size() * sizeof(index_t)}, h);
}

}  // namespace edgefem

namespace edgefem::sim {

namespace {

constexpr char kMagic[8] = {'E', 'F', 'E', 'M', 'C', 'K', 'P', 'T'};
// magic, version, file length
constexpr std::size_t kHeader = sizeof kMagic + sizeof(std::uint32_t) + sizeof(std::uint64_t);

void write_fingerprint(CheckpointWriter& w, const Fingerprint& p) {
    w.text(p.scalar);
    w.text(p.integrator);
    w.text(p.solver);
    w.text(p.numbering);
    w.value(p.vertices);
    w.value(p.tets);
    w.value(p.mesh_hash);
    w.text(p.backend);
}

Fingerprint read_fingerprint(CheckpointReader& r) {
    Fingerprint p;
    p.scalar = r.text("scalar type");
    p.integrator = r.text("integrator");
    p.solver = r.text("solver");
    p.numbering = r.text("numbering");
    p.vertices = r.value<std::uint64_t>("vertex count");
    p.tets = r.value<std::uint64_t>("tet count");
    p.mesh_hash = r.value<std::uint64_t>("mesh hash");
    p.backend = r.text("back-end");
    return p;
}

// (Appended, not "'" + ... + "'": g++ 12 warns falsely there, -Wrestrict.)
std::string quoted(const std::string& s) {
    std::string q(1, '\'');
    q += printable(s);
    q += '\'';
    return q;
}

}  // namespace

std::string checkpoint_file(const Fingerprint& print, const std::string& state) {
    CheckpointWriter w;
    w.bytes().append(kMagic, sizeof kMagic);
    w.value(kCheckpointVersion);
    w.value(std::uint64_t(0));  // the file length, below
    write_fingerprint(w, print);
    w.text(state);
    std::string& bytes = w.bytes();
    const std::uint64_t length = bytes.size() + sizeof(std::uint64_t);
    std::memcpy(bytes.data() + sizeof kMagic + sizeof(std::uint32_t), &length, sizeof length);
    w.value(fnv1a(bytes));
    return std::move(bytes);
}

std::string read_checkpoint_file(const std::string& path, const Fingerprint& expected) {
    const std::string name = "checkpoint " + quoted(path);
    const auto fail = [&](const std::string& why) -> void { throw CheckpointError(name + ": " + why, path); };
    std::ifstream in(path, std::ios::binary);
    if (!in) fail(std::string("cannot be opened: ") + std::strerror(errno));
    std::ostringstream buf;
    buf << in.rdbuf();
    if (in.bad()) fail("cannot be read");
    const std::string bytes = std::move(buf).str();
    if (bytes.size() < kHeader || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
        fail("not an edgefem checkpoint (no EFEMCKPT header)");
    CheckpointReader head(std::string_view(bytes).substr(sizeof kMagic), path);
    const auto version = head.value<std::uint32_t>("version");
    if (version != kCheckpointVersion)
        fail("format version " + std::to_string(version) + ", this build reads version " +
             std::to_string(kCheckpointVersion));
    const auto length = head.value<std::uint64_t>("file length");
    if (bytes.size() < length)
        fail("truncated: " + std::to_string(bytes.size()) + " of " + std::to_string(length) + " bytes");
    if (bytes.size() > length)
        fail(std::to_string(bytes.size()) + " bytes where the header says " + std::to_string(length) +
             " (data appended?)");
    std::uint64_t sum;
    std::memcpy(&sum, bytes.data() + length - sizeof sum, sizeof sum);
    if (fnv1a(std::string_view(bytes).substr(0, length - sizeof sum)) != sum)
        fail("corrupt: the checksum does not match its contents");
    CheckpointReader r(std::string_view(bytes).substr(kHeader, length - kHeader - sizeof sum), path);
    const Fingerprint p = read_fingerprint(r);
    const auto differs = [&](const char* what, const std::string& file, const std::string& here) {
        if (file != here)
            fail(std::string("written for ") + what + " " + quoted(file) + ", this simulator has " + quoted(here));
    };
    differs("scalar type", p.scalar, expected.scalar);
    differs("integrator", p.integrator, expected.integrator);
    differs("solver", p.solver, expected.solver);
    differs("vertex numbering", p.numbering, expected.numbering);
    if (p.vertices != expected.vertices || p.tets != expected.tets)
        fail("written for a mesh of " + std::to_string(p.vertices) + " vertices and " + std::to_string(p.tets) +
             " tets, this simulator's has " + std::to_string(expected.vertices) + " and " +
             std::to_string(expected.tets));
    if (p.mesh_hash != expected.mesh_hash)
        fail("written for another mesh of the same size (the rest positions or tets differ: mesh hash " +
             std::to_string(p.mesh_hash) + ", this simulator's " + std::to_string(expected.mesh_hash) + ")");
    std::string state = r.text("state");
    if (!r.done()) r.fail("file", "bytes after the state");
    return state;
}

}  // namespace edgefem::sim
