// tb_specfx: co-simulation testbench of specfx_dut against the golden vectors of
// `specfx vectors` and the stimulus of `specfx hdl stimulus` (docs/cycle.md).
//
// Reads from the current directory ($readmemh): in_c.hex, in_n.hex, in_slope.hex,
// in_offset.hex, in_threshold.hex, in_coef.hex, expected_out.hex (one word per vector), stim_valid.hex,
// stim_ready.hex (one bit per cycle) and expected_cycle.hex (one 32-bit word per vector).
// Macros: specfx_params.vh (formats), SPECFX_NVEC (vectors) and SPECFX_NCYC (lines of the
// stimulus files), given on the command line (-D).
//
// During cycle t (cycle 0 is the first after reset): in_valid = (vectors left) &&
// stim_valid[t], out_ready = stim_ready[t] (both 1 past the end of the files). On each output
// transfer, out_data is compared with expected_out[i] and the cycle with expected_cycle[i]; a
// vector passes when both match. The run stops when every output has arrived, or at a
// timeout (the missing outputs count as failed). A change of out_data or a drop of out_valid
// while out_valid is high and out_ready low (docs/cycle.md, rule 5) counts as one more
// failure. Prints the first 10 mismatches, then exactly one line `N passed, N failed`.
// With SPECFX_VCD defined, dumps every signal to rtl.vcd (Verilator: also --trace).
`include "specfx_params.vh"
`default_nettype none
// A testbench: blocking counters in the clocked checker and a nonblocking reset release are
// intended (the DUT only sees signals that change after a clock edge).
/* verilator lint_off BLKSEQ */
/* verilator lint_off INITIALDLY */

module tb_specfx;
    localparam integer NVEC = `SPECFX_NVEC;
    localparam integer NCYC = `SPECFX_NCYC;
    localparam integer NVEC_MEM = (NVEC > 0) ? NVEC : 1;
    localparam integer NCYC_MEM = (NCYC > 0) ? NCYC : 1;
    localparam integer C_W = `SPECFX_C_W;
    localparam integer N_W = `SPECFX_N_W;
    localparam integer SLOPE_W = `SPECFX_SLOPE_W;
    localparam integer OFFSET_W = `SPECFX_OFFSET_W;
    localparam integer COEF_W = `SPECFX_COEF_W;
    localparam integer OUT_W = `SPECFX_OUT_W;
    // Past the stimulus every cycle offers and accepts, so each vector needs at most one
    // initiation interval; the slack covers the latency.
    localparam integer PER_VECTOR = (`SPECFX_K + 2) * (`SPECFX_LAT_MUL) + (`SPECFX_LAT_SUB)
                                  + (`SPECFX_LAT_ADD) + 2;
    localparam integer TIMEOUT = NCYC + (NVEC + 8) * PER_VECTOR + 1000;
    localparam integer MAX_SHOWN = 10;

    // ---- Files. ----
    reg [C_W-1:0]      mem_c         [0:NVEC_MEM-1];
    reg [N_W-1:0]      mem_n         [0:NVEC_MEM-1];
    reg [SLOPE_W-1:0]  mem_slope     [0:NVEC_MEM-1];
    reg [OFFSET_W-1:0] mem_offset    [0:NVEC_MEM-1];
    reg [C_W-1:0]      mem_threshold [0:NVEC_MEM-1];
    reg [COEF_W-1:0]   mem_coef      [0:NVEC_MEM-1];
    reg [OUT_W-1:0]    mem_out       [0:NVEC_MEM-1];
    reg [31:0]         mem_cycle     [0:NVEC_MEM-1];
    reg                stim_valid    [0:NCYC_MEM-1];
    reg                stim_ready    [0:NCYC_MEM-1];

    initial begin
        if (NVEC > 0) begin
            $readmemh("in_c.hex", mem_c);
            $readmemh("in_n.hex", mem_n);
            $readmemh("in_slope.hex", mem_slope);
            $readmemh("in_offset.hex", mem_offset);
            $readmemh("in_threshold.hex", mem_threshold);
            $readmemh("in_coef.hex", mem_coef);
            $readmemh("expected_out.hex", mem_out);
            $readmemh("expected_cycle.hex", mem_cycle);
        end
        if (NCYC > 0) begin
            $readmemh("stim_valid.hex", stim_valid);
            $readmemh("stim_ready.hex", stim_ready);
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
    // The vector's n, for traces only (the DUT takes the per-n constants, not n).
    /* verilator lint_off UNUSEDSIGNAL */
    wire [N_W-1:0]      in_n         = (in_idx < NVEC) ? mem_n[in_idx] : {N_W{1'b0}};
    /* verilator lint_on UNUSEDSIGNAL */
    wire [SLOPE_W-1:0]  in_slope     = (in_idx < NVEC) ? mem_slope[in_idx] : {SLOPE_W{1'b0}};
    wire [OFFSET_W-1:0] in_offset    = (in_idx < NVEC) ? mem_offset[in_idx] : {OFFSET_W{1'b0}};
    wire [C_W-1:0]      in_threshold = (in_idx < NVEC) ? mem_threshold[in_idx] : {C_W{1'b0}};
    wire [COEF_W-1:0]   in_coef      = (in_idx < NVEC) ? mem_coef[in_idx] : {COEF_W{1'b0}};
    wire in_ready;
    wire out_valid;
    wire [OUT_W-1:0] out_data;

    specfx_dut dut (
        .clk(clk), .rst(rst),
        .in_valid(in_valid), .in_ready(in_ready),
        .in_c(in_c), .in_slope(in_slope), .in_offset(in_offset),
        .in_threshold(in_threshold), .in_coef(in_coef),
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
            $finish;
        end
    endtask

    always @(posedge clk) begin
        if (!rst) begin
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
