// specfx_pipelined: the `pipelined` microarchitecture of docs/cycle.md (Rust: src/cycle/).
// One operation per stage, each followed by its own delay line:
//
//   sub (LAT_SUB) -> mul_t (LAT_MUL) -> add_b (LAT_ADD) -> square_1..square_K (LAT_MUL each)
//   -> mul_out (LAT_MUL)
//
// Latency L = LAT_SUB + LAT_ADD + (K + 2) * LAT_MUL cycles. The per-n constants (slope,
// offset, threshold, coef) and the clamped input travel down beside the data as far as they
// are needed. One global enable: advance = !out_valid || out_ready; in_ready = advance; when
// advance is high every register takes the value of the one before it (the first valid bit
// takes in_valid), when it is low nothing moves.
//
// Formats: <X>_W width, <X>_F fraction bits (may be negative), <X>_S signed (0/1). The K
// squaring stages take their formats, rounding and overflow codes from 112-bit packed vectors,
// 16 bits per stage: stage i (1..7) in bits [16*i-1:16*(i-1)]; F fields are two's complement.
// Rounding codes: 0 TRN, 1 TRN_ZERO, 2 RND, 3 RND_ZERO, 4 RND_INF, 5 RND_MIN_INF, 6 RND_CONV,
// 7 RND_CONV_ODD. Overflow codes: 0 WRAP, 1 SAT, 2 SAT_ZERO, 3 SAT_SYM. Cutoff codes: 0 clamp,
// 1 paper, 2 none. RESET_DATA = 1 clears the data registers on rst too (else only the valid
// bits reset).
//
// Per-n depth (docs/arithmetic.md, section 3.1.0): `in_depth` is j(n), the number of squarings
// n uses; squaring stage i > j(n) passes its input through (specfx_sq_quant's bypass). Only
// stages i > DEPTH_MIN (the smallest depth of any n) have the multiplexer, so DEPTH_MIN >= K
// (the default, 7) is the fixed-depth datapath and in_depth is ignored. The depth rides down
// beside the coefficient; a bypassed stage keeps its place and its LAT_MUL registers, so the
// latency and the handshake are the same for every n.
`timescale 1ns / 1ps
`default_nettype none

module specfx_pipelined #(
    parameter integer K        = 4,
    parameter integer CUTOFF   = 0,
    parameter integer C_W      = 16,
    parameter integer C_F      = 15,
    parameter integer C_S      = 0,
    parameter integer D_W      = 16,
    parameter integer D_F      = 15,
    parameter integer SLOPE_W  = 11,
    parameter integer SLOPE_F  = 4,
    parameter integer SLOPE_S  = 0,
    parameter integer SLOPE_POW2 = 0,
    parameter integer OFFSET_W = 1,
    parameter integer OFFSET_F = 0,
    parameter integer OFFSET_S = 0,
    parameter integer T_W      = 18,
    parameter integer T_F      = 16,
    parameter integer T_S      = 1,
    parameter integer T_RND    = 2,
    parameter integer T_OVF    = 1,
    parameter integer B_W      = 17,
    parameter integer B_F      = 16,
    parameter integer B_S      = 0,
    parameter integer B_RND    = 2,
    parameter integer B_OVF    = 1,
    parameter [111:0] SQ_W     = {7{16'd17}},
    parameter [111:0] SQ_F     = {7{16'd16}},
    parameter [111:0] SQ_S     = {7{16'd0}},
    parameter [111:0] SQ_RND   = {7{16'd2}},
    parameter [111:0] SQ_OVF   = {7{16'd1}},
    parameter integer COEF_W   = 24,
    parameter integer COEF_F   = 16,
    parameter integer COEF_S   = 0,
    parameter integer OUT_W    = 24,
    parameter integer OUT_F    = 16,
    parameter integer OUT_S    = 0,
    parameter integer OUT_RND  = 2,
    parameter integer OUT_OVF  = 1,
    parameter integer LAT_SUB  = 1,
    parameter integer LAT_MUL  = 1,
    parameter integer LAT_ADD  = 1,
    parameter integer RESET_DATA = 0,
    parameter integer DEPTH_MIN = 7
) (
    input  wire                clk,
    input  wire                rst,
    input  wire                in_valid,
    output wire                in_ready,
    input  wire [C_W-1:0]      in_c,
    input  wire [SLOPE_W-1:0]  in_slope,
    input  wire [OFFSET_W-1:0] in_offset,
    input  wire [C_W-1:0]      in_threshold,
    input  wire [COEF_W-1:0]   in_coef,
    input  wire [2:0]          in_depth,
    output wire                out_valid,
    input  wire                out_ready,
    output wire [OUT_W-1:0]    out_data
);
    localparam integer L = LAT_SUB + LAT_ADD + (K + 2) * LAT_MUL;

    // ---- Formats of the squaring chain: stage 0 is b, stage i (1..K) is sq_i. ----
    function integer sq_field(input [111:0] packed_fields, input integer i, input integer is_signed);
        reg [15:0] f;
        begin
            f = packed_fields[16*i-1 -: 16];
            sq_field = {{16{(is_signed != 0) & f[15]}}, f};
        end
    endfunction
    function integer chain_w(input integer i);
        chain_w = (i == 0) ? B_W : sq_field(SQ_W, i, 0);
    endfunction
    function integer chain_f(input integer i);
        chain_f = (i == 0) ? B_F : sq_field(SQ_F, i, 1);
    endfunction
    function integer chain_s(input integer i);
        chain_s = (i == 0) ? B_S : sq_field(SQ_S, i, 0);
    endfunction
    // Offset of stage i's value in the packed chain bus.
    function integer chain_off(input integer i);
        integer j;
        begin
            chain_off = 0;
            for (j = 0; j < i; j = j + 1) chain_off = chain_off + chain_w(j);
        end
    endfunction

    // ---- Global enable and valid bits. ----
    wire advance = !out_valid || out_ready;
    assign in_ready = advance;
    specfx_delay #(.W(1), .LAT(L), .RESET(1)) u_valid (
        .clk(clk), .rst(rst), .en(advance), .d(in_valid), .q(out_valid)
    );

    // ---- sub: clamp c to 1.0, d = c - 1. ----
    wire [C_W-1:0] c_cl_0;
    wire [D_W-1:0] d_0;
    specfx_sub #(.C_W(C_W), .C_F(C_F), .C_S(C_S), .D_W(D_W), .D_F(D_F)) u_sub (
        .c(in_c), .c_clamped(c_cl_0), .d(d_0)
    );
    wire [D_W-1:0]      d_1;
    wire [C_W-1:0]      c_cl_1;
    wire [SLOPE_W-1:0]  slope_1;
    wire [OFFSET_W-1:0] offset_1;
    wire [C_W-1:0]      threshold_1;
    wire [COEF_W-1:0]   coef_1;
    wire [2:0]          depth_1;
    specfx_delay #(
        .W(3 + D_W + 2 * C_W + SLOPE_W + OFFSET_W + COEF_W), .LAT(LAT_SUB), .RESET(RESET_DATA)
    ) r_sub (
        .clk(clk), .rst(rst), .en(advance),
        .d({in_depth, in_coef, in_threshold, in_offset, in_slope, c_cl_0, d_0}),
        .q({depth_1, coef_1, threshold_1, offset_1, slope_1, c_cl_1, d_1})
    );

    // ---- mul_t: t = Q_t(d * slope). ----
    wire [T_W-1:0] t_1;
    specfx_mul_t #(
        .D_W(D_W), .D_F(D_F), .SLOPE_W(SLOPE_W), .SLOPE_F(SLOPE_F), .SLOPE_S(SLOPE_S),
        .T_W(T_W), .T_F(T_F), .T_S(T_S), .T_RND(T_RND), .T_OVF(T_OVF),
        .SLOPE_POW2(SLOPE_POW2)
    ) u_mul_t (
        .d(d_1), .slope(slope_1), .t(t_1)
    );
    wire [T_W-1:0]      t_2;
    wire [C_W-1:0]      c_cl_2;
    wire [OFFSET_W-1:0] offset_2;
    wire [C_W-1:0]      threshold_2;
    wire [COEF_W-1:0]   coef_2;
    wire [2:0]          depth_2;
    specfx_delay #(.W(3 + T_W + 2 * C_W + OFFSET_W + COEF_W), .LAT(LAT_MUL), .RESET(RESET_DATA)) r_mul_t (
        .clk(clk), .rst(rst), .en(advance),
        .d({depth_1, coef_1, threshold_1, offset_1, c_cl_1, t_1}),
        .q({depth_2, coef_2, threshold_2, offset_2, c_cl_2, t_2})
    );

    // ---- add_b: b = Q_b(cutoff(t + offset)). ----
    // chain[chain_off(i) +: chain_w(i)] is stage i's registered value (0: b, i: sq_i);
    // coefs[i*COEF_W +: COEF_W] is the coefficient beside it, depths[3*i +: 3] the depth.
    wire [chain_off(K + 1)-1:0] chain;
    wire [(K+1)*COEF_W-1:0]     coefs;
    wire [3*(K+1)-1:0]          depths;
    wire [B_W-1:0] b_2;
    specfx_add_b #(
        .T_W(T_W), .T_F(T_F), .T_S(T_S),
        .OFFSET_W(OFFSET_W), .OFFSET_F(OFFSET_F), .OFFSET_S(OFFSET_S),
        .C_W(C_W), .C_S(C_S), .CUTOFF(CUTOFF),
        .B_W(B_W), .B_F(B_F), .B_S(B_S), .B_RND(B_RND), .B_OVF(B_OVF)
    ) u_add_b (
        .t(t_2), .offset(offset_2), .c_clamped(c_cl_2), .threshold(threshold_2), .b(b_2)
    );
    // Each register's output goes to wires of its own, assigned into the buses: a port
    // connected to slices of two buses at once makes Verilator 5.006 report MULTIDRIVEN when
    // the buses' widths are 16, 32 or 64 bits (a false positive, but a failed lint).
    wire [2:0]        depth_b;
    wire [COEF_W-1:0] coef_b;
    wire [B_W-1:0]    b_q;
    specfx_delay #(.W(3 + B_W + COEF_W), .LAT(LAT_ADD), .RESET(RESET_DATA)) r_add_b (
        .clk(clk), .rst(rst), .en(advance),
        .d({depth_2, coef_2, b_2}),
        .q({depth_b, coef_b, b_q})
    );
    assign depths[0 +: 3] = depth_b;
    assign coefs[0 +: COEF_W] = coef_b;
    assign chain[0 +: B_W] = b_q;

    // ---- square_i, i = 1..K: sq_i = Q_i(sq_{i-1}^2), or Q_i(sq_{i-1}) when i > depth. ----
    genvar i;
    generate
        for (i = 1; i <= K; i = i + 1) begin : g_square
            localparam integer X_W = chain_w(i - 1);
            localparam integer Y_W = chain_w(i);
            wire [Y_W-1:0] y;
            wire [Y_W-1:0] y_q;
            wire [COEF_W-1:0] coef_q;
            wire [2:0] depth_q;
            wire [2:0] depth_x = depths[3*(i-1) +: 3];
            localparam integer I_I = i;
            localparam [2:0] I_CODE = I_I[2:0];
            wire pass = (depth_x < I_CODE);
            specfx_square #(
                .X_W(X_W), .X_F(chain_f(i - 1)), .X_S(chain_s(i - 1)),
                .Y_W(Y_W), .Y_F(chain_f(i)), .Y_S(chain_s(i)),
                .Y_RND(sq_field(SQ_RND, i, 0)), .Y_OVF(sq_field(SQ_OVF, i, 0)),
                .BYPASS((i > DEPTH_MIN) ? 1 : 0)
            ) u_square (
                .x(chain[chain_off(i - 1) +: X_W]), .pass(pass), .y(y)
            );
            specfx_delay #(.W(3 + Y_W + COEF_W), .LAT(LAT_MUL), .RESET(RESET_DATA)) r_square (
                .clk(clk), .rst(rst), .en(advance),
                .d({depth_x, coefs[(i-1)*COEF_W +: COEF_W], y}),
                .q({depth_q, coef_q, y_q})
            );
            assign depths[3*i +: 3] = depth_q;
            assign coefs[i*COEF_W +: COEF_W] = coef_q;
            assign chain[chain_off(i) +: Y_W] = y_q;
        end
    endgenerate

    // ---- mul_out: out = Q_out(sq_K * coef). ----
    wire [OUT_W-1:0] out_k;
    specfx_mul_out #(
        .X_W(chain_w(K)), .X_F(chain_f(K)), .X_S(chain_s(K)),
        .COEF_W(COEF_W), .COEF_F(COEF_F), .COEF_S(COEF_S),
        .OUT_W(OUT_W), .OUT_F(OUT_F), .OUT_S(OUT_S), .OUT_RND(OUT_RND), .OUT_OVF(OUT_OVF)
    ) u_mul_out (
        .x(chain[chain_off(K) +: chain_w(K)]), .coef(coefs[K*COEF_W +: COEF_W]), .out(out_k)
    );
    specfx_delay #(.W(OUT_W), .LAT(LAT_MUL), .RESET(RESET_DATA)) r_mul_out (
        .clk(clk), .rst(rst), .en(advance), .d(out_k), .q(out_data)
    );
    // The depth past the last stage, and all of it when no stage has a bypass, goes nowhere
    // (synthesis removes its registers).
    wire _unused_ok = &{1'b0, depths};
endmodule

`default_nettype wire
