// specfx_top: the parameterized top of the reference RTL, with the ports of docs/cycle.md.
// Every width, mode, k, cutoff and latency is a Verilog parameter, so cocotb, VUnit, FuseSoC
// and vendor tools set them per instance (`specfx hdl params --format json|iverilog|verilator
// |instance` prints a configuration's values); the defaults are the baseline, pipelined.
// ARCH picks the microarchitecture: 0 pipelined (specfx_pipelined), 1 folded (specfx_folded).
//
// Formats: <X>_W width, <X>_F fraction bits (may be negative), <X>_S 1 when two's complement.
// Squaring stage i (1..7) is SQi_W/_F/_S/_RND/_OVF (stages above K are ignored). Rounding
// codes: 0 TRN, 1 TRN_ZERO, 2 RND, 3 RND_ZERO, 4 RND_INF, 5 RND_MIN_INF, 6 RND_CONV,
// 7 RND_CONV_ODD. Overflow codes: 0 WRAP, 1 SAT, 2 SAT_ZERO, 3 SAT_SYM. Cutoff codes: 0 clamp,
// 1 paper, 2 none. The folded core uses LAT_MUL only (LAT_SUB, LAT_ADD and SLOPE_POW2 are
// pipelined-only).
//
// RESET_DATA = 1 also clears the data registers (and so out_data) on the synchronous,
// active-high rst; with 0 (the default, cheaper) only the control registers and valid bits
// reset, and out_data is unknown until the first result.
//
// Per-n depth (docs/arithmetic.md, section 3.1.0): in_depth is j(n), the squarings n uses (a
// 3-bit field of the per-n ROM, beside the other constants); squaring stage i > j(n) passes its
// input through. DEPTH_MIN is the smallest j(n) of the configuration: stages up to it have no
// multiplexer, and DEPTH_MIN >= K (the default, 7) is the fixed-depth datapath, whose in_depth
// is ignored.
`timescale 1ns / 1ps
`default_nettype none

module specfx_top #(
    parameter integer ARCH       = 0,
    parameter integer K          = 4,
    parameter integer CUTOFF     = 0,
    parameter integer C_W        = 16,
    parameter integer C_F        = 15,
    parameter integer C_S        = 0,
    parameter integer D_W        = 16,
    parameter integer D_F        = 15,
    parameter integer SLOPE_W    = 11,
    parameter integer SLOPE_F    = 4,
    parameter integer SLOPE_S    = 0,
    parameter integer SLOPE_POW2 = 0,
    parameter integer OFFSET_W   = 1,
    parameter integer OFFSET_F   = 0,
    parameter integer OFFSET_S   = 0,
    parameter integer T_W        = 18,
    parameter integer T_F        = 16,
    parameter integer T_S        = 1,
    parameter integer T_RND      = 2,
    parameter integer T_OVF      = 1,
    parameter integer B_W        = 17,
    parameter integer B_F        = 16,
    parameter integer B_S        = 0,
    parameter integer B_RND      = 2,
    parameter integer B_OVF      = 1,
    parameter integer SQ1_W = 17, parameter integer SQ1_F = 16, parameter integer SQ1_S = 0,
    parameter integer SQ1_RND = 2, parameter integer SQ1_OVF = 1,
    parameter integer SQ2_W = 17, parameter integer SQ2_F = 16, parameter integer SQ2_S = 0,
    parameter integer SQ2_RND = 2, parameter integer SQ2_OVF = 1,
    parameter integer SQ3_W = 17, parameter integer SQ3_F = 16, parameter integer SQ3_S = 0,
    parameter integer SQ3_RND = 2, parameter integer SQ3_OVF = 1,
    parameter integer SQ4_W = 17, parameter integer SQ4_F = 16, parameter integer SQ4_S = 0,
    parameter integer SQ4_RND = 2, parameter integer SQ4_OVF = 1,
    parameter integer SQ5_W = 17, parameter integer SQ5_F = 16, parameter integer SQ5_S = 0,
    parameter integer SQ5_RND = 2, parameter integer SQ5_OVF = 1,
    parameter integer SQ6_W = 17, parameter integer SQ6_F = 16, parameter integer SQ6_S = 0,
    parameter integer SQ6_RND = 2, parameter integer SQ6_OVF = 1,
    parameter integer SQ7_W = 17, parameter integer SQ7_F = 16, parameter integer SQ7_S = 0,
    parameter integer SQ7_RND = 2, parameter integer SQ7_OVF = 1,
    parameter integer COEF_W     = 24,
    parameter integer COEF_F     = 16,
    parameter integer COEF_S     = 0,
    parameter integer OUT_W      = 24,
    parameter integer OUT_F      = 16,
    parameter integer OUT_S      = 0,
    parameter integer OUT_RND    = 2,
    parameter integer OUT_OVF    = 1,
    parameter integer LAT_SUB    = 1,
    parameter integer LAT_MUL    = 1,
    parameter integer LAT_ADD    = 1,
    parameter integer RESET_DATA = 0,
    parameter integer DEPTH_MIN  = 7
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
    // The cores take the squaring stages as 112-bit vectors, 16 bits per stage, stage i in
    // bits [16*i-1:16*(i-1)] (F fields two's complement).
    localparam [111:0] SQ_W = {SQ7_W[15:0], SQ6_W[15:0], SQ5_W[15:0], SQ4_W[15:0],
                               SQ3_W[15:0], SQ2_W[15:0], SQ1_W[15:0]};
    localparam [111:0] SQ_F = {SQ7_F[15:0], SQ6_F[15:0], SQ5_F[15:0], SQ4_F[15:0],
                               SQ3_F[15:0], SQ2_F[15:0], SQ1_F[15:0]};
    localparam [111:0] SQ_S = {SQ7_S[15:0], SQ6_S[15:0], SQ5_S[15:0], SQ4_S[15:0],
                               SQ3_S[15:0], SQ2_S[15:0], SQ1_S[15:0]};
    localparam [111:0] SQ_RND = {SQ7_RND[15:0], SQ6_RND[15:0], SQ5_RND[15:0], SQ4_RND[15:0],
                                 SQ3_RND[15:0], SQ2_RND[15:0], SQ1_RND[15:0]};
    localparam [111:0] SQ_OVF = {SQ7_OVF[15:0], SQ6_OVF[15:0], SQ5_OVF[15:0], SQ4_OVF[15:0],
                                 SQ3_OVF[15:0], SQ2_OVF[15:0], SQ1_OVF[15:0]};

    generate
        if (ARCH == 0) begin : g_pipelined
            specfx_pipelined #(
                .K(K), .CUTOFF(CUTOFF),
                .C_W(C_W), .C_F(C_F), .C_S(C_S), .D_W(D_W), .D_F(D_F),
                .SLOPE_W(SLOPE_W), .SLOPE_F(SLOPE_F), .SLOPE_S(SLOPE_S), .SLOPE_POW2(SLOPE_POW2),
                .OFFSET_W(OFFSET_W), .OFFSET_F(OFFSET_F), .OFFSET_S(OFFSET_S),
                .T_W(T_W), .T_F(T_F), .T_S(T_S), .T_RND(T_RND), .T_OVF(T_OVF),
                .B_W(B_W), .B_F(B_F), .B_S(B_S), .B_RND(B_RND), .B_OVF(B_OVF),
                .SQ_W(SQ_W), .SQ_F(SQ_F), .SQ_S(SQ_S), .SQ_RND(SQ_RND), .SQ_OVF(SQ_OVF),
                .COEF_W(COEF_W), .COEF_F(COEF_F), .COEF_S(COEF_S),
                .OUT_W(OUT_W), .OUT_F(OUT_F), .OUT_S(OUT_S), .OUT_RND(OUT_RND), .OUT_OVF(OUT_OVF),
                .LAT_SUB(LAT_SUB), .LAT_MUL(LAT_MUL), .LAT_ADD(LAT_ADD),
                .RESET_DATA(RESET_DATA), .DEPTH_MIN(DEPTH_MIN)
            ) u_core (
                .clk(clk), .rst(rst),
                .in_valid(in_valid), .in_ready(in_ready),
                .in_c(in_c), .in_slope(in_slope), .in_offset(in_offset),
                .in_threshold(in_threshold), .in_coef(in_coef), .in_depth(in_depth),
                .out_valid(out_valid), .out_ready(out_ready), .out_data(out_data)
            );
        end else begin : g_folded
            specfx_folded #(
                .K(K), .CUTOFF(CUTOFF),
                .C_W(C_W), .C_F(C_F), .C_S(C_S), .D_W(D_W), .D_F(D_F),
                .SLOPE_W(SLOPE_W), .SLOPE_F(SLOPE_F), .SLOPE_S(SLOPE_S),
                .OFFSET_W(OFFSET_W), .OFFSET_F(OFFSET_F), .OFFSET_S(OFFSET_S),
                .T_W(T_W), .T_F(T_F), .T_S(T_S), .T_RND(T_RND), .T_OVF(T_OVF),
                .B_W(B_W), .B_F(B_F), .B_S(B_S), .B_RND(B_RND), .B_OVF(B_OVF),
                .SQ_W(SQ_W), .SQ_F(SQ_F), .SQ_S(SQ_S), .SQ_RND(SQ_RND), .SQ_OVF(SQ_OVF),
                .COEF_W(COEF_W), .COEF_F(COEF_F), .COEF_S(COEF_S),
                .OUT_W(OUT_W), .OUT_F(OUT_F), .OUT_S(OUT_S), .OUT_RND(OUT_RND), .OUT_OVF(OUT_OVF),
                .LAT_MUL(LAT_MUL),
                .RESET_DATA(RESET_DATA), .DEPTH_MIN(DEPTH_MIN)
            ) u_core (
                .clk(clk), .rst(rst),
                .in_valid(in_valid), .in_ready(in_ready),
                .in_c(in_c), .in_slope(in_slope), .in_offset(in_offset),
                .in_threshold(in_threshold), .in_coef(in_coef), .in_depth(in_depth),
                .out_valid(out_valid), .out_ready(out_ready), .out_data(out_data)
            );
            wire _unused_ok = &{1'b0, LAT_SUB[0], LAT_ADD[0], SLOPE_POW2[0]};
        end
    endgenerate
endmodule

`default_nettype wire
