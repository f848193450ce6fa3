#pragma once
// Messages of the MPI module as bytes: trivially copyable values, arrays and strings, in
// the host's byte order (all ranks of a job run the same binary).
#include <mpi.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "splat/error.h"

namespace splat::mpi {

struct Writer {
    std::vector<char> bytes;
    template <class T>
    void put(const T& v) {
        static_assert(std::is_trivially_copyable_v<T>);
        putArray(&v, 1);
    }
    template <class T>
    void putArray(const T* p, std::size_t n) {
        const char* c = reinterpret_cast<const char*>(p);
        bytes.insert(bytes.end(), c, c + n * sizeof(T));
    }
    void putString(const std::string& s) {
        put(std::uint64_t(s.size()));
        putArray(s.data(), s.size());
    }
};

struct Reader {
    const std::vector<char>& bytes;
    std::size_t at = 0;
    explicit Reader(const std::vector<char>& b) : bytes(b) {}
    template <class T>
    T get() {
        T v;
        getArray(&v, 1);
        return v;
    }
    template <class T>
    void getArray(T* p, std::size_t n) {
        if (n * sizeof(T) > bytes.size() - at) throw Error("MPI: a message ended early");
        std::memcpy(static_cast<void*>(p), bytes.data() + at, n * sizeof(T));
        at += n * sizeof(T);
    }
    std::string getString() {
        std::string s(get<std::uint64_t>(), '\0');
        getArray(s.data(), s.size());
        return s;
    }
};

/// Receives the message of `tag` from `source` whatever its length.
inline std::vector<char> receiveBytes(int source, int tag) {
    MPI_Status st;
    MPI_Probe(source, tag, MPI_COMM_WORLD, &st);
    int n = 0;
    MPI_Get_count(&st, MPI_BYTE, &n);
    std::vector<char> b(static_cast<std::size_t>(n));
    MPI_Recv(b.data(), n, MPI_BYTE, st.MPI_SOURCE, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    return b;
}

}  // namespace splat::mpi
