// tb_specfx_dpi: a constrained-random testbench of specfx_top whose scoreboard asks specfx's
// model, through DPI-C (specfx_dpi.sv), for the expected value of whatever input it just drove.
//
// Parameters: every parameter of specfx_top (`specfx hdl params --format verilator` prints a
// configuration's values), passed to the DUT instance `dut`. Plusargs:
//   +config=ARG    the model, as specfx's --config takes it (a built-in name, a TOML file, a
//                  vector directory); the same configuration as the parameters
//   +seed=S        the seed of the stimulus (default 1)
//   +nvec=N        random vectors to drive after the directed ones (default 10000)
//   +bubble=P      percent of random cycles the source does not offer its pending vector
//                  (default 25)
//   +stall=P       percent of random cycles out_ready is low, in bursts (default 25)
//   +exhaustive    every code of the input format up to 1.0 for every n of the configuration
//                  (n changing on every vector), instead of random vectors (the codes above 1.0
//                  all clamp to 1.0: the directed vectors hold them); no bubbles or stalls
//                  besides the directed episodes unless given
//
// The handshake pattern (docs/cycle.md, "The handshake pattern", as specfx hdl stimulus draws
// it): a block of directed episodes (an output stalled from its first cycle for longer than an
// initiation interval while inputs come back to back at the interval, a stall that ends on the
// cycle a new input is offered, a one-cycle stall, a stall in a stream), each after a drain,
// then 4096 random cycles (bubbles drawn per cycle, stalls in bursts of 1..2B-1 cycles,
// B = the initiation interval + 1), repeated.
//
// The directed vectors come first: the cases `specfx vectors` always writes (every n's corner
// cases, codes with a non-zero output, inputs on and next to every stage's rounding boundary),
// interleaved. Random vectors draw n from the configuration's set on every input, and c uniformly over every
// code, near 1.0 (above it included), on and next to the cutoff's boundary and the paper
// threshold, at the ends of the code range, and below 1.0. A vector's per-n constants drive
// in_slope, in_offset, in_threshold, in_coef and in_depth, as a ROM addressed by n would.
//
// The scoreboard: when an input transfers, its expected output (specfx_dpi_eval) is queued;
// each output transfer is checked against the head of the queue. Every cycle, the cycle model
// (specfx_dpi_machine_cycle, docs/cycle.md) says what in_ready, out_valid and the output's
// input number must be, so every output is also checked on its cycle; out_data must hold
// while out_valid is high and out_ready low (rule 5), and with RESET_DATA = 1 be 0 in cycle 0.
// Prints the first 10 mismatches, a
// coverage line, then exactly one line `N passed, N failed` (a vector passes when its output
// has the expected value on the expected cycle; protocol errors count as failures too); then
// ends with $finish when every vector passed, and with $fatal when a check failed or nothing
// was checked (a non-zero exit status: the model Verilator builds aborts).
`timescale 1ns / 1ps
`default_nettype none
/* verilator lint_off BLKSEQ */
/* verilator lint_off INITIALDLY */

module tb_specfx_dpi #(
    parameter integer ARCH = 0, parameter integer K = 4, parameter integer CUTOFF = 0,
    parameter integer C_W = 16, parameter integer C_F = 15, parameter integer C_S = 0,
    parameter integer D_W = 16, parameter integer D_F = 15, parameter integer SLOPE_W = 11,
    parameter integer SLOPE_F = 4, parameter integer SLOPE_S = 0, parameter integer SLOPE_POW2 = 0,
    parameter integer OFFSET_W = 1, parameter integer OFFSET_F = 0, parameter integer OFFSET_S = 0,
    parameter integer T_W = 18, parameter integer T_F = 16, parameter integer T_S = 1,
    parameter integer T_RND = 2, parameter integer T_OVF = 1, parameter integer B_W = 17,
    parameter integer B_F = 16, parameter integer B_S = 0, parameter integer B_RND = 2,
    parameter integer B_OVF = 1, parameter integer SQ1_W = 17, parameter integer SQ1_F = 16,
    parameter integer SQ1_S = 0, parameter integer SQ1_RND = 2, parameter integer SQ1_OVF = 1,
    parameter integer SQ2_W = 17, parameter integer SQ2_F = 16, parameter integer SQ2_S = 0,
    parameter integer SQ2_RND = 2, parameter integer SQ2_OVF = 1, parameter integer SQ3_W = 17,
    parameter integer SQ3_F = 16, parameter integer SQ3_S = 0, parameter integer SQ3_RND = 2,
    parameter integer SQ3_OVF = 1, parameter integer SQ4_W = 17, parameter integer SQ4_F = 16,
    parameter integer SQ4_S = 0, parameter integer SQ4_RND = 2, parameter integer SQ4_OVF = 1,
    parameter integer SQ5_W = 17, parameter integer SQ5_F = 16, parameter integer SQ5_S = 0,
    parameter integer SQ5_RND = 2, parameter integer SQ5_OVF = 1, parameter integer SQ6_W = 17,
    parameter integer SQ6_F = 16, parameter integer SQ6_S = 0, parameter integer SQ6_RND = 2,
    parameter integer SQ6_OVF = 1, parameter integer SQ7_W = 17, parameter integer SQ7_F = 16,
    parameter integer SQ7_S = 0, parameter integer SQ7_RND = 2, parameter integer SQ7_OVF = 1,
    parameter integer COEF_W = 24, parameter integer COEF_F = 16, parameter integer COEF_S = 0,
    parameter integer OUT_W = 24, parameter integer OUT_F = 16, parameter integer OUT_S = 0,
    parameter integer OUT_RND = 2, parameter integer OUT_OVF = 1, parameter integer LAT_SUB = 1,
    parameter integer LAT_MUL = 1, parameter integer LAT_ADD = 1, parameter integer RESET_DATA = 0,
    parameter integer DEPTH_MIN = 7
);
    import specfx_dpi::*;

    localparam integer MAX_SHOWN = 10;
    localparam integer PER_VECTOR = (K + 2) * LAT_MUL + LAT_SUB + LAT_ADD + 2;

    // ---- Clock and reset: rst is high for 4 edges, then released. ----
    reg clk = 1'b0;
    reg rst = 1'b1;
    always #5 clk = ~clk;
    initial begin
        repeat (4) @(posedge clk);
        rst <= 1'b0;
    end

    // ---- The model, the plusargs, the stimulus generator. ----
    chandle model;
    chandle machine;
    string cfg;
    longint unsigned state = 64'h9E3779B97F4A7C15;
    longint seed = 1;
    longint nvec = 10000;
    int bubble = 25;
    int stall = 25;
    bit exhaustive = 0;
    longint c_min, c_max, c_one;
    int n_count;
    int n_values[];
    // The per-n constants as specfx_top's ports take them, by index into n_values (a ROM).
    longint rom_slope[], rom_offset[], rom_threshold[], rom_coef[], rom_depth[];
    longint total;  // vectors to drive
    int n_directed = 0;

    // xorshift64*: the same stream in every simulator.
    function automatic longint unsigned rnd();
        state = state ^ (state >> 12);
        state = state ^ (state << 25);
        state = state ^ (state >> 27);
        return state * 64'h2545F4914F6CDD1D;
    endfunction

    function automatic int percent();
        return int'(rnd() % 100);
    endfunction

    task automatic die(input string what);
        $display("specfx_dpi: %s: %s", what, specfx_dpi_last_error());
        $fatal(1);
    endtask

    // A code clamped to the input format.
    function automatic longint clamp_code(input longint c);
        if (c < c_min) return c_min;
        if (c > c_max) return c_max;
        return c;
    endfunction

    // A code drawn uniformly from lo..hi.
    function automatic longint uniform(input longint lo, input longint hi);
        longint unsigned span = longint'(hi - lo) + 1;
        if (span == 0) return longint'(rnd());  // all 2^64 codes
        return lo + longint'(rnd() % span);
    endfunction

    bit seen_n[];  // the n that transferred, by index
    initial begin
        longint v;
        if (!$value$plusargs("config=%s", cfg)) begin
            $display("specfx_dpi: +config=ARG is missing (the model, as specfx --config takes it)");
            $fatal(1);
        end
        void'($value$plusargs("seed=%d", seed));
        void'($value$plusargs("nvec=%d", nvec));
        exhaustive = $test$plusargs("exhaustive");
        if (exhaustive) begin
            bubble = 0;
            stall = 0;
        end
        void'($value$plusargs("bubble=%d", bubble));
        void'($value$plusargs("stall=%d", stall));
        state = state ^ (longint'(seed) * 64'hBF58476D1CE4E5B9);
        if (state == 0) state = 1;
        model = specfx_dpi_open(cfg);
        if (model == null) die("the model");
        machine = specfx_dpi_machine_new(model, ARCH);
        if (machine == null) die("the cycle model");
        if (specfx_dpi_input_codes(model, c_min, c_max, c_one) != 0) die("the input codes");
        n_count = specfx_dpi_n_count(model);
        n_values = new[n_count];
        rom_slope = new[n_count];
        rom_offset = new[n_count];
        rom_threshold = new[n_count];
        rom_coef = new[n_count];
        rom_depth = new[n_count];
        seen_n = new[n_count];
        for (int i = 0; i < n_count; i++) begin
            n_values[i] = specfx_dpi_n_at(model, i);
            if (specfx_dpi_constant(model, n_values[i], 0, v) != 0) die("the slope");
            rom_slope[i] = v;
            if (specfx_dpi_constant(model, n_values[i], 1, v) != 0) die("the offset");
            rom_offset[i] = v;
            if (specfx_dpi_constant(model, n_values[i], 2, v) != 0) die("the threshold");
            rom_threshold[i] = v;
            if (specfx_dpi_constant(model, n_values[i], 3, v) != 0) die("the coefficient");
            rom_coef[i] = v;
            if (specfx_dpi_constant(model, n_values[i], 4, v) != 0) die("the depth");
            rom_depth[i] = v;
        end
        if (exhaustive) begin
            if (longint'(c_one - c_min) >= 64'h1_0000_0000) begin
                $display("specfx_dpi: +exhaustive: %0d input codes is too many to drive",
                         c_one - c_min + 1);
                $fatal(1);
            end
            total = (c_one - c_min + 1) * n_count;
        end else begin
            n_directed = specfx_dpi_directed_count(model);
            if (n_directed < 0) die("the directed cases");
            total = n_directed + nvec;
        end
    end

    // ---- The handshake pattern: (offer, out_ready) per cycle. ----
    localparam integer LATENCY = (ARCH == 0) ? LAT_SUB + LAT_ADD + (K + 2) * LAT_MUL
                                             : (K + 2) * LAT_MUL + 1;
    localparam integer II = (ARCH == 0) ? 1 : (K + 2) * LAT_MUL;
    localparam integer BURST = II + 1;  // the mean length of a stall burst
    localparam integer RANDOM_CYCLES = 4096;
    bit block_offer[$];
    bit block_ready[$];
    longint hs_cycle = 0;
    longint burst_left = 0;

    // One episode after its drain: offers at `offers`, out_ready low for stall_len cycles
    // from stall_at.
    task automatic add_episode(input int offers[], input int stall_at, input int stall_len);
        int last = stall_at + stall_len - 1;
        bit offered;
        foreach (offers[i]) if (offers[i] > last) last = offers[i];
        for (int t = 0; t < LATENCY + II + 2; t++) begin
            block_offer.push_back(1'b0);
            block_ready.push_back(1'b1);
        end
        for (int t = 0; t <= last; t++) begin
            offered = 1'b0;
            foreach (offers[i]) if (offers[i] == t) offered = 1'b1;
            block_offer.push_back(offered);
            block_ready.push_back(!(t >= stall_at && t < stall_at + stall_len));
        end
    endtask

    initial begin
        int offers[];
        offers = new[4];
        foreach (offers[i]) offers[i] = i * II;
        add_episode(offers, LATENCY, II + 1);
        offers = new[2];
        offers[0] = 0;
        offers[1] = LATENCY + II + 1;
        add_episode(offers, LATENCY, II + 1);
        offers[1] = 1;
        add_episode(offers, LATENCY, 1);
        offers = new[2 * II + 1];
        foreach (offers[i]) offers[i] = i;
        add_episode(offers, LATENCY + 1, II + 1);
    end

    // The next cycle's offer and out_ready: the block, then the random cycles.
    task automatic handshake_next(output bit offer, output bit ready);
        longint phase = hs_cycle % (block_offer.size() + RANDOM_CYCLES);
        hs_cycle = hs_cycle + 1;
        if (phase < block_offer.size()) begin
            burst_left = 0;
            offer = block_offer[phase];
            ready = block_ready[phase];
        end else begin
            offer = percent() >= bubble;
            if (burst_left > 0) begin
                burst_left = burst_left - 1;
                ready = 1'b0;
            end else if (stall > 0
                         && longint'(rnd() % longint'(stall + BURST * (100 - stall))) < stall) begin
                burst_left = longint'(rnd() % longint'(2 * BURST - 1));
                ready = 1'b0;
            end else begin
                ready = 1'b1;
            end
        end
    endtask

    // ---- The DUT's inputs: the offered vector, held until it transfers (rule 2). ----
    reg in_valid = 1'b0;
    reg out_ready = 1'b0;
    longint cur_c = 0;
    int cur_n = 0;
    int cur_idx = 0;
    reg [C_W-1:0]      in_c = '0;
    reg [SLOPE_W-1:0]  in_slope = '0;
    reg [OFFSET_W-1:0] in_offset = '0;
    reg [C_W-1:0]      in_threshold = '0;
    reg [COEF_W-1:0]   in_coef = '0;
    reg [2:0]          in_depth = '0;
    wire in_ready;
    wire out_valid;
    wire [OUT_W-1:0] out_data;

    specfx_top #(
        .ARCH(ARCH), .K(K), .CUTOFF(CUTOFF), .C_W(C_W), .C_F(C_F), .C_S(C_S), .D_W(D_W), .D_F(D_F),
        .SLOPE_W(SLOPE_W), .SLOPE_F(SLOPE_F), .SLOPE_S(SLOPE_S), .SLOPE_POW2(SLOPE_POW2), .OFFSET_W(OFFSET_W),
        .OFFSET_F(OFFSET_F), .OFFSET_S(OFFSET_S), .T_W(T_W), .T_F(T_F), .T_S(T_S), .T_RND(T_RND),
        .T_OVF(T_OVF), .B_W(B_W), .B_F(B_F), .B_S(B_S), .B_RND(B_RND), .B_OVF(B_OVF), .SQ1_W(SQ1_W),
        .SQ1_F(SQ1_F), .SQ1_S(SQ1_S), .SQ1_RND(SQ1_RND), .SQ1_OVF(SQ1_OVF), .SQ2_W(SQ2_W),
        .SQ2_F(SQ2_F), .SQ2_S(SQ2_S), .SQ2_RND(SQ2_RND), .SQ2_OVF(SQ2_OVF), .SQ3_W(SQ3_W),
        .SQ3_F(SQ3_F), .SQ3_S(SQ3_S), .SQ3_RND(SQ3_RND), .SQ3_OVF(SQ3_OVF), .SQ4_W(SQ4_W),
        .SQ4_F(SQ4_F), .SQ4_S(SQ4_S), .SQ4_RND(SQ4_RND), .SQ4_OVF(SQ4_OVF), .SQ5_W(SQ5_W),
        .SQ5_F(SQ5_F), .SQ5_S(SQ5_S), .SQ5_RND(SQ5_RND), .SQ5_OVF(SQ5_OVF), .SQ6_W(SQ6_W),
        .SQ6_F(SQ6_F), .SQ6_S(SQ6_S), .SQ6_RND(SQ6_RND), .SQ6_OVF(SQ6_OVF), .SQ7_W(SQ7_W),
        .SQ7_F(SQ7_F), .SQ7_S(SQ7_S), .SQ7_RND(SQ7_RND), .SQ7_OVF(SQ7_OVF), .COEF_W(COEF_W),
        .COEF_F(COEF_F), .COEF_S(COEF_S), .OUT_W(OUT_W), .OUT_F(OUT_F), .OUT_S(OUT_S), .OUT_RND(OUT_RND),
        .OUT_OVF(OUT_OVF), .LAT_SUB(LAT_SUB), .LAT_MUL(LAT_MUL), .LAT_ADD(LAT_ADD), .RESET_DATA(RESET_DATA),
        .DEPTH_MIN(DEPTH_MIN)
    ) dut (
        .clk(clk), .rst(rst),
        .in_valid(in_valid), .in_ready(in_ready),
        .in_c(in_c), .in_slope(in_slope), .in_offset(in_offset),
        .in_threshold(in_threshold), .in_coef(in_coef), .in_depth(in_depth),
        .out_valid(out_valid), .out_ready(out_ready), .out_data(out_data)
    );

    // The next vector: exhaustive (code-major, n changing on every vector) or random.
    longint drawn = 0;
    task automatic next_vector();
        longint c;
        int n;
        longint v;
        int idx;
        if (exhaustive) begin
            idx = int'(drawn % longint'(n_count));
            n = n_values[idx];
            c = c_min + drawn / n_count;
        end else if (drawn < n_directed) begin
            if (specfx_dpi_directed_at(model, int'(drawn), n, c) != 0) die("a directed case");
            idx = 0;
            while (n_values[idx] != n) idx = idx + 1;
        end else begin
            idx = int'(rnd() % longint'(n_count));
            n = n_values[idx];
            case (rnd() % 8)
                0, 1: c = uniform(c_min, c_max);
                2: c = clamp_code(c_one + longint'(rnd() % 5) - 2);
                3: begin
                    if (specfx_dpi_first_live(model, n, v) != 0) die("the cutoff boundary");
                    c = clamp_code(v + longint'(rnd() % 5) - 2);
                end
                4: c = clamp_code(rom_threshold[idx] + longint'(rnd() % 5) - 2);
                5: c = (rnd() % 2 == 0) ? c_min : c_max;
                default: c = uniform(c_min, c_one);
            endcase
        end
        drawn = drawn + 1;
        cur_c <= c;
        cur_n <= n;
        cur_idx <= idx;
        in_c <= c[C_W-1:0];
        in_slope <= rom_slope[idx][SLOPE_W-1:0];
        in_offset <= rom_offset[idx][OFFSET_W-1:0];
        in_threshold <= rom_threshold[idx][C_W-1:0];
        in_coef <= rom_coef[idx][COEF_W-1:0];
        in_depth <= rom_depth[idx][2:0];
    endtask

    // ---- The scoreboard. ----
    longint expected[$];  // outputs of the inputs that transferred and have not come out
    longint cycle = 0;
    longint n_in = 0, n_out = 0, n_passed = 0, n_failed = 0, n_shown = 0;
    longint n_nonzero = 0, n_stalls = 0, n_bubbles = 0, n_above_one = 0;
    longint n_distinct = 0;
    reg held = 1'b0;
    bit pending = 0;  // a vector is drawn and has not transferred yet
    reg [OUT_W-1:0] held_data;

    task automatic fail(input string what);
        n_failed = n_failed + 1;
        if (n_shown < MAX_SHOWN) $display("%s", what);
        n_shown = n_shown + 1;
    endtask

    task automatic finish();
        $display("coverage: %0d vectors checked (%0d directed), %0d of %0d n, %0d non-zero outputs, %0d stall cycles, %0d bubbles, %0d inputs above 1.0",
                 n_out, n_directed, n_distinct, n_count, n_nonzero, n_stalls, n_bubbles, n_above_one);
        $display("%0d passed, %0d failed", n_passed, n_failed);
        specfx_dpi_machine_free(machine);
        specfx_dpi_free(model);
        if (n_failed != 0 || n_passed == 0) $fatal(1, "tb_specfx_dpi: the check failed");
        $finish;
    endtask

    int m_in_ready, m_out_valid;
    bit offer, ready;
    longint m_out_data, m_out_tag, want;
    string how;
    always @(posedge clk) begin
        if (!rst) begin
            // What the ports must show during this cycle, by the cycle model.
            if (specfx_dpi_machine_cycle(machine, int'(in_valid), cur_c, cur_n, int'(out_ready),
                                         m_in_ready, m_out_valid, m_out_data, m_out_tag) != 0)
                die("the cycle model");
            if (in_ready !== m_in_ready[0])
                fail($sformatf("protocol: cycle %0d: in_ready=%b, the cycle model says %0d", cycle,
                               in_ready, m_in_ready));
            if (out_valid !== m_out_valid[0])
                fail($sformatf("protocol: cycle %0d: out_valid=%b, the cycle model says %0d", cycle,
                               out_valid, m_out_valid));
            if (RESET_DATA != 0 && cycle == 0 && out_data !== {OUT_W{1'b0}})
                fail($sformatf("protocol: out_data=%h after reset with RESET_DATA=1, want 0",
                               out_data));
            if (held && (!out_valid || out_data !== held_data))
                fail($sformatf("protocol: out_valid/out_data changed while stalled, cycle=%0d",
                               cycle));
            held <= out_valid && !out_ready;
            held_data <= out_data;
            if (!out_ready) n_stalls = n_stalls + 1;
            // An input transfer: its expected output joins the queue.
            if (in_valid && in_ready) begin
                if (specfx_dpi_eval(model, cur_c, cur_n, want) != 0) die("the expected output");
                expected.push_back(want);
                if (!seen_n[cur_idx]) n_distinct = n_distinct + 1;
                seen_n[cur_idx] = 1;
                if (cur_c > c_one) n_above_one = n_above_one + 1;
                n_in = n_in + 1;
            end
            // An output transfer: checked against the head of the queue, and on its cycle.
            if (out_valid && out_ready) begin
                if (expected.size() == 0) begin
                    fail($sformatf("unexpected output at cycle %0d: no input is left", cycle));
                end else begin
                    want = expected.pop_front();
                    if (out_data === want[OUT_W-1:0] && m_out_valid != 0 && m_out_tag == n_out) begin
                        n_passed = n_passed + 1;
                        if (want != 0) n_nonzero = n_nonzero + 1;
                    end else begin
                        how = (m_out_valid != 0 && m_out_tag == n_out)
                            ? "agrees on the cycle" : "expects it on another cycle";
                        fail($sformatf("mismatch i=%0d got=%h want=%h cycle=%0d (the cycle model %s)",
                                       n_out, out_data, want[OUT_W-1:0], cycle, how));
                    end
                end
                n_out = n_out + 1;
                if (n_out >= total) finish();
            end
            // The next cycle's stimulus: the pending vector (drawn once its predecessor has
            // transferred, held until it transfers) is offered or not, cycle by cycle.
            if (in_valid && in_ready) pending = 0;
            if (!pending && drawn < total) begin
                next_vector();
                pending = 1;
            end
            handshake_next(offer, ready);
            if (pending && offer) begin
                in_valid <= 1'b1;
            end else begin
                if (pending) n_bubbles = n_bubbles + 1;
                in_valid <= 1'b0;
            end
            out_ready <= ready;
            if (total == 0) finish();
            if (cycle > 1000 + total * PER_VECTOR * 4) begin
                $display("timeout at cycle %0d: %0d of %0d outputs arrived", cycle, n_out, total);
                n_failed = n_failed + (total - n_out);
                finish();
            end
            cycle = cycle + 1;
        end
    end
endmodule

`default_nettype wire
