// tb_specfx: co-simulation testbench of specfx_top against the golden vectors of
// `specfx vectors` and the stimulus of `specfx hdl stimulus` (docs/cycle.md).
//
// Reads ($readmemh) in_c.hex, in_n.hex, in_slope.hex, in_offset.hex, in_threshold.hex,
// in_coef.hex, in_depth.hex, expected_out.hex (one word per vector) from the directory of the plusarg
// +vectors=DIR, and stim_valid.hex, stim_ready.hex (one bit per cycle) and expected_cycle.hex
// (one 32-bit word per vector) from that of +stimulus=DIR; each defaults to the current
// directory (paths up to 500 characters). Parameters (set per run: iverilog -Ptb_specfx.<NAME>=<value>, verilator
// -G<NAME>=<value>; `specfx hdl params --format iverilog --top tb_specfx` prints them):
// NVEC (vectors: n_vectors of the vector directory's manifest.json), NCYC (lines of the
// stimulus files: n_cycles of stim.json) and every parameter of specfx_top, passed to the DUT
// instance `dut`. NVEC and NCYC have no default: the testbench counts the words of in_c.hex
// and stim_valid.hex, and refuses to run ($fatal, with the count it found) when NVEC or NCYC
// is not set or differs from its file's count, or when the file cannot be opened.
// Defining SPECFX_VCD dumps every signal to rtl.vcd.
//
// During cycle t (cycle 0 is the first after reset): in_valid = (vectors left) &&
// stim_valid[t], out_ready = stim_ready[t] (both 1 past the end of the files); the input ports
// show the next vector also while in_valid is low (zeros after the last). On each output
// transfer, out_data is compared with expected_out[i] and the cycle with expected_cycle[i]; a
// vector passes when both match. The run stops when every output has arrived, or at a
// timeout (the missing outputs count as failed). A change of out_data or a drop of out_valid
// while out_valid is high and out_ready low (docs/cycle.md, rule 5) counts as one more
// failure, and so do, with RESET_DATA = 1, an out_data other than 0 in cycle 0, and in any
// cycle an X or Z on in_ready or out_valid, or on out_data while out_valid is high. Prints the
// first 10 mismatches, then exactly one line `N passed, N failed`; then ends with $finish when
// every vector passed, and with $fatal (a non-zero exit status: vvp exits with 1, a Verilator
// model aborts) when a check failed or nothing was checked.
`timescale 1ns / 1ps
`default_nettype none
// A testbench: blocking counters in the clocked checker and a nonblocking reset release are
// intended (the DUT only sees signals that change after a clock edge).
/* verilator lint_off BLKSEQ */
/* verilator lint_off INITIALDLY */

module tb_specfx #(
    parameter integer NVEC = -1, parameter integer NCYC = -1,
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
    localparam integer NVEC_MEM = (NVEC > 0) ? NVEC : 1;
    localparam integer NCYC_MEM = (NCYC > 0) ? NCYC : 1;
    // in_n is not a DUT port (the per-n constants are); the testbench shows it in traces.
    localparam integer N_W = 32;
    // Past the stimulus every cycle offers and accepts, so each vector needs at most one
    // initiation interval; the slack covers the latency.
    localparam integer PER_VECTOR = (K + 2) * LAT_MUL + LAT_SUB + LAT_ADD + 2;
    localparam integer TIMEOUT = NCYC + (NVEC + 8) * PER_VECTOR + 1000;
    localparam integer MAX_SHOWN = 10;

    // ---- Files. ----
    reg [C_W-1:0]      mem_c         [0:NVEC_MEM-1];
    reg [N_W-1:0]      mem_n         [0:NVEC_MEM-1];
    reg [SLOPE_W-1:0]  mem_slope     [0:NVEC_MEM-1];
    reg [OFFSET_W-1:0] mem_offset    [0:NVEC_MEM-1];
    reg [C_W-1:0]      mem_threshold [0:NVEC_MEM-1];
    reg [COEF_W-1:0]   mem_coef      [0:NVEC_MEM-1];
    reg [2:0]          mem_depth     [0:NVEC_MEM-1];
    reg [OUT_W-1:0]    mem_out       [0:NVEC_MEM-1];
    reg [31:0]         mem_cycle     [0:NVEC_MEM-1];
    reg                stim_valid    [0:NCYC_MEM-1];
    reg                stim_ready    [0:NCYC_MEM-1];

    // The directories of the vector and the stimulus files (plusargs), and a file's path.
    reg [8*500-1:0] vec_dir, stim_dir;
    reg [8*520-1:0] path;
    // The number of hex words in a file, -1 when it cannot be opened.
    task count_words(input [8*520-1:0] file, output integer n);
        integer fd, got;
        reg [63:0] word;
        begin
            n = 0;
            fd = $fopen(file, "r");
            if (fd == 0) begin
                n = -1;
            end else begin
                got = $fscanf(fd, "%h", word);
                while (got == 1) begin
                    n = n + 1;
                    got = $fscanf(fd, "%h", word);
                end
                $fclose(fd);
            end
        end
    endtask

    // Refuses a count parameter that is not set or does not match its file.
    task check_count(input [8*520-1:0] file, input integer words, input integer want,
                     input [8*4-1:0] name, input [8*40-1:0] source);
        begin
            if (words < 0) begin
                $display("tb_specfx: cannot open %0s", file);
                $fatal(1, "tb_specfx: a file is missing");
            end else if (want < 0) begin
                $display("tb_specfx: %0s is not set: expected %0s (%0s holds %0d words)", name,
                         source, file, words);
                $fatal(1, "tb_specfx: a count is not set");
            end else if (words != want) begin
                $display("tb_specfx: %0s = %0d, but %0s holds %0d words (expected %0s)", name,
                         want, file, words, source);
                $fatal(1, "tb_specfx: a count does not match its file");
            end
        end
    endtask

    integer n_words;
    initial begin
        if (!$value$plusargs("vectors=%s", vec_dir)) vec_dir = ".";
        if (!$value$plusargs("stimulus=%s", stim_dir)) stim_dir = ".";
        $sformat(path, "%0s/in_c.hex", vec_dir);
        count_words(path, n_words);
        check_count(path, n_words, NVEC, "NVEC", "n_vectors of manifest.json");
        $sformat(path, "%0s/stim_valid.hex", stim_dir);
        count_words(path, n_words);
        check_count(path, n_words, NCYC, "NCYC", "n_cycles of stim.json");
        if (NVEC > 0) begin
            $sformat(path, "%0s/in_c.hex", vec_dir);         $readmemh(path, mem_c);
            $sformat(path, "%0s/in_n.hex", vec_dir);         $readmemh(path, mem_n);
            $sformat(path, "%0s/in_slope.hex", vec_dir);     $readmemh(path, mem_slope);
            $sformat(path, "%0s/in_offset.hex", vec_dir);    $readmemh(path, mem_offset);
            $sformat(path, "%0s/in_threshold.hex", vec_dir); $readmemh(path, mem_threshold);
            $sformat(path, "%0s/in_coef.hex", vec_dir);      $readmemh(path, mem_coef);
            $sformat(path, "%0s/in_depth.hex", vec_dir);     $readmemh(path, mem_depth);
            $sformat(path, "%0s/expected_out.hex", vec_dir); $readmemh(path, mem_out);
            $sformat(path, "%0s/expected_cycle.hex", stim_dir);
            $readmemh(path, mem_cycle);
        end
        if (NCYC > 0) begin
            $sformat(path, "%0s/stim_valid.hex", stim_dir);  $readmemh(path, stim_valid);
            $sformat(path, "%0s/stim_ready.hex", stim_dir);  $readmemh(path, stim_ready);
        end
    end

    // ---- Clock and reset: rst is high for 4 edges, then released. ----
    reg clk = 1'b0;
    reg rst = 1'b1;
    always #5 clk = ~clk;
    initial begin
        repeat (4) @(posedge clk);
        rst <= 1'b0;
    end

    // ---- Drive. Everything the DUT sees changes only after a clock edge (nonblocking). ----
    integer cycle = 0;    // the current cycle number (0 = first cycle after reset)
    integer in_idx = 0;   // next vector to offer
    integer out_idx = 0;  // next output expected
    wire offer = (cycle < NCYC) ? stim_valid[cycle] : 1'b1;
    wire in_valid = !rst && (in_idx < NVEC) && offer;
    wire out_ready = !rst && ((cycle < NCYC) ? stim_ready[cycle] : 1'b1);
    wire [C_W-1:0]      in_c         = (in_idx < NVEC) ? mem_c[in_idx] : {C_W{1'b0}};
    wire [N_W-1:0]      in_n         = (in_idx < NVEC) ? mem_n[in_idx] : {N_W{1'b0}};
    wire [SLOPE_W-1:0]  in_slope     = (in_idx < NVEC) ? mem_slope[in_idx] : {SLOPE_W{1'b0}};
    wire [OFFSET_W-1:0] in_offset    = (in_idx < NVEC) ? mem_offset[in_idx] : {OFFSET_W{1'b0}};
    wire [C_W-1:0]      in_threshold = (in_idx < NVEC) ? mem_threshold[in_idx] : {C_W{1'b0}};
    wire [COEF_W-1:0]   in_coef      = (in_idx < NVEC) ? mem_coef[in_idx] : {COEF_W{1'b0}};
    wire [2:0]          in_depth     = (in_idx < NVEC) ? mem_depth[in_idx] : 3'd0;
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

`ifdef SPECFX_VCD
    initial begin
        $dumpfile("rtl.vcd");
        $dumpvars(0, tb_specfx);
    end
`endif

    // ---- Check. ----
    integer n_passed = 0;
    integer n_failed = 0;
    integer n_shown = 0;
    reg held = 1'b0;              // last cycle ended with out_valid && !out_ready
    reg [OUT_W-1:0] held_data;

    task report_and_finish;
        begin
            $display("%0d passed, %0d failed", n_passed, n_failed);
            if (n_failed != 0 || n_passed == 0)
                $fatal(1, "tb_specfx: the check failed");
            $finish;
        end
    endtask

    always @(posedge clk) begin
        if (!rst) begin
            if (RESET_DATA != 0 && cycle == 0 && out_data !== {OUT_W{1'b0}}) begin
                n_failed = n_failed + 1;
                if (n_shown < MAX_SHOWN)
                    $display("protocol: out_data=%h after reset with RESET_DATA=1, want 0", out_data);
                n_shown = n_shown + 1;
            end
            if ((^{in_ready, out_valid}) === 1'bx) begin
                n_failed = n_failed + 1;
                if (n_shown < MAX_SHOWN)
                    $display("protocol: cycle %0d: in_ready=%b out_valid=%b, an X or Z", cycle,
                             in_ready, out_valid);
                n_shown = n_shown + 1;
            end
            if (out_valid === 1'b1 && (^out_data) === 1'bx) begin
                n_failed = n_failed + 1;
                if (n_shown < MAX_SHOWN)
                    $display("protocol: cycle %0d: out_data=%h while out_valid is high, an X or Z",
                             cycle, out_data);
                n_shown = n_shown + 1;
            end
            if (held && (!out_valid || out_data !== held_data)) begin
                n_failed = n_failed + 1;
                if (n_shown < MAX_SHOWN)
                    $display("protocol: out_valid/out_data changed while stalled, cycle=%0d", cycle);
                n_shown = n_shown + 1;
            end
            held <= out_valid && !out_ready;
            held_data <= out_data;
            if (in_valid && in_ready) in_idx <= in_idx + 1;
            if (out_valid && out_ready) begin
                if (out_idx < NVEC) begin
                    if (out_data === mem_out[out_idx] && cycle == mem_cycle[out_idx]) begin
                        n_passed = n_passed + 1;
                    end else begin
                        n_failed = n_failed + 1;
                        if (n_shown < MAX_SHOWN)
                            $display("mismatch i=%0d c=%h got=%h want=%h cycle=%0d want_cycle=%0d",
                                     out_idx, mem_c[out_idx], out_data, mem_out[out_idx], cycle,
                                     mem_cycle[out_idx]);
                        n_shown = n_shown + 1;
                    end
                end else begin
                    n_failed = n_failed + 1;
                    if (n_shown < MAX_SHOWN)
                        $display("unexpected output %0d got=%h cycle=%0d", out_idx, out_data, cycle);
                    n_shown = n_shown + 1;
                end
                out_idx <= out_idx + 1;
                if (out_idx + 1 >= NVEC) report_and_finish;
            end
            if (NVEC == 0) report_and_finish;
            if (cycle >= TIMEOUT) begin
                $display("timeout at cycle %0d: %0d of %0d outputs arrived", cycle, out_idx, NVEC);
                n_failed = n_failed + (NVEC - out_idx);
                report_and_finish;
            end
            cycle <= cycle + 1;
        end
    end
endmodule

`default_nettype wire
