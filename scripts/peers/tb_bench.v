// tb_bench: the Icarus Verilog driver of scripts/bench-peers. Streams every input code
// c_raw = 0..=2^C_F (up to 1.0, C_F = `SPECFX_C_F of specfx_params.vh; 0..=32768 for the
// baseline's u1.15) for each n of a constants file through specfx_dut (hdl_ref/, pipelined),
// with in_valid and out_ready high on every cycle, and sums out_raw * (c_raw + 1) * n
// (mod 2^64) per n, pairing each output with its input by order (docs/cycle.md, rule 4).
//
// Plusargs: +consts=FILE (one line per n, decimal: n slope offset threshold coef; at most
// 1024 lines), optional +dump=FILE (every output as "n c_raw out_raw").
// Prints "n N SUM" per n, then "evaluations E" and "cycles C".
`include "specfx_params.vh"
`default_nettype none

module tb_bench;
    localparam integer C_W = `SPECFX_C_W;
    localparam integer SLOPE_W = `SPECFX_SLOPE_W;
    localparam integer OFFSET_W = `SPECFX_OFFSET_W;
    localparam integer COEF_W = `SPECFX_COEF_W;
    localparam integer OUT_W = `SPECFX_OUT_W;
    localparam integer CODES = (1 << `SPECFX_C_F) + 1;  // c_raw = 0..=2^C_F
    localparam integer MAXN = 1024;

    reg clk = 1'b0;
    reg rst = 1'b1;
    reg in_valid = 1'b0;
    reg out_ready = 1'b1;
    reg [C_W-1:0] in_c = 0;
    reg [SLOPE_W-1:0] in_slope = 0;
    reg [OFFSET_W-1:0] in_offset = 0;
    reg [C_W-1:0] in_threshold = 0;
    reg [COEF_W-1:0] in_coef = 0;
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

    reg [63:0] k_n [0:MAXN-1];
    reg [63:0] k_slope [0:MAXN-1];
    reg [63:0] k_offset [0:MAXN-1];
    reg [63:0] k_threshold [0:MAXN-1];
    reg [63:0] k_coef [0:MAXN-1];
    reg [63:0] sums [0:MAXN-1];

    reg [1023:0] path;
    integer fd, dump, got, nk, i;
    reg [63:0] a, b, c, d, e;
    reg [63:0] total, in_idx, out_idx, cycles, acc, out64;
    integer in_n, out_n, in_code, out_code;

    initial begin
        if (!$value$plusargs("consts=%s", path)) begin
            $display("error: +consts=FILE is required");
            $finish;
        end
        fd = $fopen(path, "r");
        if (fd == 0) begin
            $display("error: cannot open the constants file");
            $finish;
        end
        nk = 0;
        got = 5;
        while (got == 5 && nk < MAXN) begin
            got = $fscanf(fd, "%d %d %d %d %d\n", a, b, c, d, e);
            if (got == 5) begin
                k_n[nk] = a; k_slope[nk] = b; k_offset[nk] = c; k_threshold[nk] = d;
                k_coef[nk] = e;
                nk = nk + 1;
            end
        end
        $fclose(fd);
        dump = 0;
        if ($value$plusargs("dump=%s", path)) dump = $fopen(path, "w");

        // Reset: 4 rising edges with rst high.
        for (i = 0; i < 4; i = i + 1) begin
            #1 clk = 1'b1;
            #1 clk = 1'b0;
        end
        rst = 1'b0;

        total = nk * CODES;
        in_idx = 0; out_idx = 0; cycles = 0; acc = 0;
        in_n = 0; out_n = 0; in_code = 0; out_code = 0;
        while (out_idx < total) begin
            // Inputs for this cycle, then let the logic settle with clk low.
            in_valid = (in_idx < total);
            if (in_idx < total) begin
                in_c = in_code;
                in_slope = k_slope[in_n];
                in_offset = k_offset[in_n];
                in_threshold = k_threshold[in_n];
                in_coef = k_coef[in_n];
            end
            #1;
            if (out_valid) begin  // out_ready is high: the output transfers at this edge
                out64 = out_data;
                acc = acc + out64 * (out_code + 1) * k_n[out_n];
                if (dump != 0) $fwrite(dump, "%0d %0d %0d\n", k_n[out_n], out_code, out_data);
                out_idx = out_idx + 1;
                out_code = out_code + 1;
                if (out_code == CODES) begin
                    sums[out_n] = acc;
                    acc = 0;
                    out_code = 0;
                    out_n = out_n + 1;
                end
            end
            if (in_valid && !in_ready) begin
                $display("error: in_ready low with out_ready high");
                $finish;
            end
            clk = 1'b1;
            #1 clk = 1'b0;
            cycles = cycles + 1;
            if (in_valid) begin
                in_idx = in_idx + 1;
                in_code = in_code + 1;
                if (in_code == CODES) begin
                    in_code = 0;
                    in_n = in_n + 1;
                end
            end
            if (cycles > total + 1000) begin
                $display("error: outputs missing");
                $finish;
            end
        end
        if (dump != 0) $fclose(dump);
        for (i = 0; i < nk; i = i + 1) $display("n %0d %0d", k_n[i], sums[i]);
        $display("evaluations %0d", out_idx);
        $display("cycles %0d", cycles);
        $finish;
    end
endmodule

`default_nettype wire
