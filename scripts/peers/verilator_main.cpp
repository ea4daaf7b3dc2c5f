// Verilator harness of scripts/bench-peers: streams every input code c_raw = 0..=2^C_F (up to
// 1.0; 0..=32768 for the baseline's u1.15) for each n of a constants file through specfx_dut
// (hdl_ref/, pipelined), with in_valid and out_ready high on every cycle, and sums
// out_raw * (c_raw + 1) * n (mod 2^64) per n, pairing each accepted output with its input by
// order (docs/cycle.md, rule 4). C_F, the input's fraction bits, is the macro SPECFX_C_F
// (`-CFLAGS -DSPECFX_C_F=F`, as `specfx hdl params` gives it; default 15, the baseline's).
//
// Usage: Vspecfx_dut CONSTS RESULTS [DUMP]
//   CONSTS   one line per n, decimal: n slope offset threshold coef (the per-n inputs)
//   RESULTS  written: "cycles C", "evaluations E", "seconds S", then "n N SUM" per n
//   DUMP     optional: every output as "n c_raw out_raw"
// The timed part is the streaming loop alone (reset, then every cycle until the last output).
#include <chrono>
#include <cinttypes>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <vector>

#include "Vspecfx_dut.h"
#include "verilated.h"

namespace {
struct Consts {
    uint64_t n, slope, offset, threshold, coef;
};
#ifndef SPECFX_C_F
#define SPECFX_C_F 15
#endif
static_assert(SPECFX_C_F >= 0 && SPECFX_C_F <= 30, "SPECFX_C_F: the input's fraction bits");
constexpr uint32_t kCodes = (uint32_t(1) << SPECFX_C_F) + 1;  // c_raw = 0..=2^C_F (up to 1.0)

[[noreturn]] void die(const char* what) {
    std::fprintf(stderr, "verilator harness: %s\n", what);
    std::exit(2);
}
}  // namespace

int main(int argc, char** argv) {
    if (argc < 3 || argc > 4) die("usage: Vspecfx_dut CONSTS RESULTS [DUMP]");
    std::vector<Consts> consts;
    {
        FILE* f = std::fopen(argv[1], "r");
        if (!f) die("cannot open the constants file");
        Consts k{};
        while (std::fscanf(f, "%" SCNu64 " %" SCNu64 " %" SCNu64 " %" SCNu64 " %" SCNu64, &k.n,
                           &k.slope, &k.offset, &k.threshold, &k.coef) == 5)
            consts.push_back(k);
        std::fclose(f);
    }
    if (consts.empty()) die("no constants read");
    FILE* dump = nullptr;
    if (argc == 4 && !(dump = std::fopen(argv[3], "w"))) die("cannot open the dump file");

    auto ctx = std::make_unique<VerilatedContext>();
    auto dut = std::make_unique<Vspecfx_dut>(ctx.get());
    const uint64_t total = uint64_t(consts.size()) * kCodes;
    std::vector<uint64_t> sums(consts.size(), 0);

    // One cycle: inputs set and the design settled with clk low (out_valid/out_data are the
    // last register's, in_ready follows out_ready), then the rising edge.
    const auto t0 = std::chrono::steady_clock::now();
    dut->rst = 1;
    dut->in_valid = 0;
    dut->out_ready = 1;
    for (int i = 0; i < 4; ++i) {
        dut->clk = 0;
        dut->eval();
        dut->clk = 1;
        dut->eval();
    }
    dut->rst = 0;

    uint64_t cycles = 0, in_idx = 0, out_idx = 0;
    size_t in_n = 0, out_n = 0;    // index of the n of the next input / of the next output
    uint32_t in_c = 0, out_c = 0;  // code of the next input / of the next output
    uint64_t acc = 0;              // the running sum of the current output n
    size_t loaded = SIZE_MAX;      // the n whose constants are on the ports
    while (out_idx < total) {
        const bool offer = in_idx < total;
        dut->clk = 0;
        dut->in_valid = offer;
        if (offer) {
            dut->in_c = in_c;
            if (loaded != in_n) {
                loaded = in_n;
                dut->in_slope = consts[in_n].slope;
                dut->in_offset = consts[in_n].offset;
                dut->in_threshold = consts[in_n].threshold;
                dut->in_coef = consts[in_n].coef;
            }
        }
        dut->eval();
        if (dut->out_valid) {  // out_ready is high: this output transfers at the edge
            const uint64_t out = dut->out_data;
            acc += out * (uint64_t(out_c) + 1) * consts[out_n].n;
            if (dump)
                std::fprintf(dump, "%" PRIu64 " %u %" PRIu64 "\n", consts[out_n].n, out_c, out);
            ++out_idx;
            if (++out_c == kCodes) {
                out_c = 0;
                sums[out_n++] = acc;
                acc = 0;
            }
        }
        if (offer && !dut->in_ready) die("in_ready low with out_ready high");
        dut->clk = 1;
        dut->eval();
        ++cycles;
        if (offer) {  // the input transferred at this edge
            ++in_idx;
            if (++in_c == kCodes) {
                in_c = 0;
                ++in_n;
            }
        }
        if (cycles > total + 1000) die("outputs missing");
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    dut->final();
    if (dump) std::fclose(dump);

    FILE* r = std::fopen(argv[2], "w");
    if (!r) die("cannot write the results file");
    std::fprintf(r, "cycles %" PRIu64 "\nevaluations %" PRIu64 "\nseconds %.9f\n", cycles,
                 out_idx, seconds);
    for (size_t i = 0; i < consts.size(); ++i)
        std::fprintf(r, "n %" PRIu64 " %" PRIu64 "\n", consts[i].n, sums[i]);
    std::fclose(r);
    return 0;
}
