// directlab_sampler.hpp: serve a sampler written in C++ to `directlab check-sampler`.
// A single header without dependencies (C++17).
//
//     #include "directlab_sampler.hpp"
//     int main(int argc, char **argv) {
//         directlab::Sampler s;
//         s.sample = [](const double *u, const directlab::Params &, double *x) {
//             double r = std::sqrt(u[0]), phi = 2 * M_PI * u[1];
//             x[0] = r * std::cos(phi); x[1] = r * std::sin(phi);
//             return true;                        // false: sampling failed
//         };
//         s.pdf = [](const double *x, const directlab::Params &) {
//             return x[0] * x[0] + x[1] * x[1] <= 1 ? 1 / M_PI : 0.0;
//         };
//         return directlab::serve(s, argc, argv);
//     }
//
//     directlab check-sampler --domain disk -- ./my_sampler
//
// directlab sends the uniform numbers (u[0..dims)), asks for the pdf where it needs it and
// does all the statistics. Points have 2 coordinates on the square, disk and triangle, 3 for
// directions (unit vectors). A BSDF (--domain bsdf) also sets `eval` (f * cos(theta_o)) and
// may set `sample_weighted` to return the weight its renderer uses. Parameters of the case
// (`wi`, `alpha`, `vertices`, every --param) are in the Params.
//
// Protocol (the same messages over both transports):
// - pipe: each request is a JSON header line {"phase", "domain", "count", "dim",
//   "point_dim", "params"} then count x dim little-endian f64; each reply a JSON header line
//   {"count", "cols"} then count x cols f64. {"phase": "end"} ends the program.
// - files: the program is run with the path of a .json request (the same header plus
//   "input" and "output", .npy files of count x dim and count x cols f64).
// A "sample" reply has columns point..., pdf, valid (1 or 0)[, weight]; "pdf" and "eval"
// replies one column.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace directlab {

/// A JSON value (enough of JSON for directlab's headers).
struct Json {
    enum Kind { Null, Bool, Number, String, Array, Object } kind = Null;
    double number = 0;
    bool boolean = false;
    std::string string;
    std::vector<Json> array;
    std::map<std::string, Json> object;

    const Json *get(const std::string &key) const {
        auto it = object.find(key);
        return kind == Object && it != object.end() ? &it->second : nullptr;
    }

    static Json parse(const std::string &text) {
        size_t i = 0;
        Json v = parse_value(text, i);
        skip(text, i);
        if (i != text.size()) fail(text, i, "trailing characters");
        return v;
    }

  private:
    [[noreturn]] static void fail(const std::string &t, size_t i, const char *what) {
        throw std::runtime_error("directlab_sampler: bad JSON header (" + std::string(what) +
                                 " at byte " + std::to_string(i) + "): " + t.substr(0, 200));
    }
    static void skip(const std::string &t, size_t &i) {
        while (i < t.size() && std::isspace((unsigned char) t[i])) ++i;
    }
    static std::string parse_string(const std::string &t, size_t &i) {
        std::string s;
        ++i;  // the opening quote
        while (i < t.size() && t[i] != '"') {
            char c = t[i++];
            if (c == '\\' && i < t.size()) {
                char e = t[i++];
                switch (e) {
                    case 'n': s += '\n'; break;
                    case 't': s += '\t'; break;
                    case 'u': s += '?'; i += 4; break;  // not in directlab's headers
                    default: s += e;
                }
            } else {
                s += c;
            }
        }
        if (i >= t.size()) fail(t, i, "unterminated string");
        ++i;
        return s;
    }
    static Json parse_value(const std::string &t, size_t &i) {
        skip(t, i);
        if (i >= t.size()) fail(t, i, "unexpected end");
        Json v;
        char c = t[i];
        if (c == '{') {
            v.kind = Object;
            ++i;
            skip(t, i);
            if (t[i] == '}') { ++i; return v; }
            for (;;) {
                skip(t, i);
                if (i >= t.size() || t[i] != '"') fail(t, i, "expected a key");
                std::string key = parse_string(t, i);
                skip(t, i);
                if (i >= t.size() || t[i] != ':') fail(t, i, "expected ':'");
                ++i;
                v.object[key] = parse_value(t, i);
                skip(t, i);
                if (i < t.size() && t[i] == ',') { ++i; continue; }
                if (i < t.size() && t[i] == '}') { ++i; return v; }
                fail(t, i, "expected ',' or '}'");
            }
        }
        if (c == '[') {
            v.kind = Array;
            ++i;
            skip(t, i);
            if (t[i] == ']') { ++i; return v; }
            for (;;) {
                v.array.push_back(parse_value(t, i));
                skip(t, i);
                if (i < t.size() && t[i] == ',') { ++i; continue; }
                if (i < t.size() && t[i] == ']') { ++i; return v; }
                fail(t, i, "expected ',' or ']'");
            }
        }
        if (c == '"') {
            v.kind = String;
            v.string = parse_string(t, i);
            return v;
        }
        for (const char *word : {"true", "false", "null"}) {
            if (t.compare(i, std::strlen(word), word) == 0) {
                i += std::strlen(word);
                v.kind = word[0] == 'n' ? Null : Bool;
                v.boolean = word[0] == 't';
                return v;
            }
        }
        const char *start = t.c_str() + i;
        char *end = nullptr;
        v.number = std::strtod(start, &end);
        if (end == start) fail(t, i, "expected a value");
        v.kind = Number;
        i += end - start;
        return v;
    }
};

/// The case's parameters: `wi`, `alpha`, `vertices`, ... and every --param.
struct Params {
    Json json;
    /// A number, or `fallback` when absent.
    double num(const std::string &key, double fallback = NAN) const {
        const Json *v = json.get(key);
        return v && v->kind == Json::Number ? v->number : fallback;
    }
    /// An array of numbers (empty when absent); `vec("wi")` is the incident direction.
    std::vector<double> vec(const std::string &key) const {
        std::vector<double> out;
        if (const Json *v = json.get(key))
            for (const Json &x : v->array) out.push_back(x.number);
        return out;
    }
    /// A string, or `fallback`.
    std::string str(const std::string &key, const std::string &fallback = "") const {
        const Json *v = json.get(key);
        return v && v->kind == Json::String ? v->string : fallback;
    }
};

/// The sampler under test. `sample` (or `sample_weighted`) and `pdf` are required.
struct Sampler {
    /// Writes the point for uniform numbers u; false when sampling fails.
    std::function<bool(const double *u, const Params &, double *point)> sample;
    /// As `sample`, also writing the sample's weight (f cos / pdf for a BSDF).
    std::function<bool(const double *u, const Params &, double *point, double *weight)>
        sample_weighted;
    /// Density at a point (per unit area, or per steradian for directions).
    std::function<double(const double *point, const Params &)> pdf;
    /// A BSDF's f * cos(theta_o) at an outgoing direction (--domain bsdf).
    std::function<double(const double *point, const Params &)> eval;
};

namespace detail {

inline void check_little_endian() {
    const uint16_t one = 1;
    if (*reinterpret_cast<const uint8_t *>(&one) != 1)
        throw std::runtime_error("directlab_sampler: this host is big-endian; the protocol "
                                 "is little-endian f64");
}

/// The reply to one request: rows of `cols` values.
inline std::vector<double> answer(const Sampler &s, const Json &head, const double *in,
                                  size_t &cols) {
    auto field = [&](const char *k) -> const Json & {
        const Json *v = head.get(k);
        if (!v) throw std::runtime_error(std::string("directlab_sampler: header lacks ") + k);
        return *v;
    };
    const std::string phase = field("phase").string;
    const size_t n = (size_t) field("count").number, dim = (size_t) field("dim").number;
    Params params;
    if (const Json *p = head.get("params")) params.json = *p;
    std::vector<double> out;
    if (phase == "sample") {
        const size_t pd = (size_t) field("point_dim").number;
        const bool weighted = bool(s.sample_weighted);
        cols = pd + 2 + (weighted ? 1 : 0);
        out.assign(n * cols, 0.0);
        std::vector<double> x(pd);
        for (size_t i = 0; i < n; ++i) {
            std::fill(x.begin(), x.end(), 0.0);
            double w = 0;
            bool ok = weighted ? s.sample_weighted(in + i * dim, params, x.data(), &w)
                               : s.sample(in + i * dim, params, x.data());
            for (double c : x) ok = ok && std::isfinite(c);
            double *row = out.data() + i * cols;
            if (!ok) continue;
            std::copy(x.begin(), x.end(), row);
            row[pd] = s.pdf(x.data(), params);
            row[pd + 1] = 1.0;
            if (weighted) row[pd + 2] = w;
        }
    } else if (phase == "pdf" || phase == "eval") {
        const auto &f = phase == "pdf" ? s.pdf : s.eval;
        if (!f)
            throw std::runtime_error("directlab_sampler: directlab asks for eval (a BSDF "
                                     "check) but the Sampler has no eval");
        cols = 1;
        out.resize(n);
        for (size_t i = 0; i < n; ++i) out[i] = f(in + i * dim, params);
    } else {
        throw std::runtime_error("directlab_sampler: unknown phase " + phase);
    }
    return out;
}

inline std::vector<double> read_npy(const std::string &path) {
    std::ifstream f(path, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    if (bytes.size() < 10 || bytes.compare(0, 6, "\x93NUMPY") != 0)
        throw std::runtime_error("directlab_sampler: " + path + " is not a .npy file");
    size_t len = bytes[6] == 1 ? (uint8_t) bytes[8] | ((uint8_t) bytes[9] << 8)
                               : *reinterpret_cast<const uint32_t *>(bytes.data() + 8);
    size_t start = (bytes[6] == 1 ? 10 : 12) + len;
    if (bytes.find("'<f8'") == std::string::npos)
        throw std::runtime_error("directlab_sampler: " + path + " is not little-endian f64");
    std::vector<double> v((bytes.size() - start) / 8);
    std::memcpy(v.data(), bytes.data() + start, v.size() * 8);
    return v;
}

inline void write_npy(const std::string &path, const std::vector<double> &v, size_t cols) {
    std::string header = "{'descr': '<f8', 'fortran_order': False, 'shape': (" +
                         std::to_string(cols ? v.size() / cols : 0) + ", " +
                         std::to_string(cols) + "), }";
    size_t unpadded = 10 + header.size() + 1;
    header += std::string((64 - unpadded % 64) % 64, ' ') + "\n";
    std::string tmp = path + ".part.npy";
    {
        std::ofstream f(tmp, std::ios::binary);
        f.write("\x93NUMPY\x01\x00", 8);
        uint16_t len = (uint16_t) header.size();
        f.put(char(len & 0xff)).put(char(len >> 8));
        f << header;
        f.write(reinterpret_cast<const char *>(v.data()), std::streamsize(v.size() * 8));
        if (!f) throw std::runtime_error("directlab_sampler: cannot write " + tmp);
    }
    if (std::rename(tmp.c_str(), path.c_str()) != 0)
        throw std::runtime_error("directlab_sampler: cannot rename " + tmp + " to " + path);
}

inline int serve_files(const Sampler &s, const std::string &request) {
    std::ifstream f(request);
    std::stringstream text;
    text << f.rdbuf();
    Json head = Json::parse(text.str());
    std::vector<double> in = read_npy(head.get("input")->string);
    size_t cols = 0;
    std::vector<double> out = answer(s, head, in.data(), cols);
    write_npy(head.get("output")->string, out, cols);
    return 0;
}

inline int serve_pipe(const Sampler &s) {
    std::string line;
    std::vector<double> in;
    for (;;) {
        line.clear();
        int c;
        while ((c = std::fgetc(stdin)) != EOF && c != '\n') line += char(c);
        if (line.empty() && c == EOF) return 0;
        Json head = Json::parse(line);
        if (head.get("phase") && head.get("phase")->string == "end") return 0;
        size_t n = (size_t) head.get("count")->number, dim = (size_t) head.get("dim")->number;
        in.resize(n * dim);
        if (std::fread(in.data(), 8, n * dim, stdin) != n * dim) return 0;
        size_t cols = 0;
        std::vector<double> out = answer(s, head, in.data(), cols);
        std::string reply = "{\"count\": " + std::to_string(n) +
                            ", \"cols\": " + std::to_string(cols) + "}\n";
        std::fwrite(reply.data(), 1, reply.size(), stdout);
        std::fwrite(out.data(), 8, out.size(), stdout);
        std::fflush(stdout);
    }
}

}  // namespace detail

/// Answers directlab: one request file when the last argument is a .json path (the files
/// transport), else requests on stdin until "end". Returns main's exit code.
inline int serve(const Sampler &s, int argc, char **argv) {
    try {
        detail::check_little_endian();
        if (!s.pdf || !(s.sample || s.sample_weighted))
            throw std::runtime_error("directlab_sampler: set sample (or sample_weighted) "
                                     "and pdf");
        std::string last = argc > 1 ? argv[argc - 1] : "";
        if (last.size() > 5 && last.compare(last.size() - 5, 5, ".json") == 0)
            return detail::serve_files(s, last);
        return detail::serve_pipe(s);
    } catch (const std::exception &e) {
        std::fprintf(stderr, "%s\n", e.what());
        return 2;
    }
}

}  // namespace directlab
