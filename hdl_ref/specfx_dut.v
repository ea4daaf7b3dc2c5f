// specfx_dut: a convenience top for `define flows. It includes specfx_params.vh (written by
// `specfx hdl params`: one `SPECFX_<NAME> macro per parameter of specfx_top) and instantiates
// specfx_top with those values; the ports are specfx_top's (docs/cycle.md). Flows that set
// Verilog parameters per instance use hdl_ref/rtl/specfx_top.v directly.
`include "specfx_params.vh"
`timescale 1ns / 1ps
`default_nettype none

module specfx_dut (
    input  wire                         clk,
    input  wire                         rst,
    input  wire                         in_valid,
    output wire                         in_ready,
    input  wire [(`SPECFX_C_W)-1:0]      in_c,
    input  wire [(`SPECFX_SLOPE_W)-1:0]  in_slope,
    input  wire [(`SPECFX_OFFSET_W)-1:0] in_offset,
    input  wire [(`SPECFX_C_W)-1:0]      in_threshold,
    input  wire [(`SPECFX_COEF_W)-1:0]   in_coef,
    input  wire [2:0]                   in_depth,
    output wire                         out_valid,
    input  wire                         out_ready,
    output wire [(`SPECFX_OUT_W)-1:0]    out_data
);
    specfx_top #(
        .ARCH((`SPECFX_ARCH)), .K((`SPECFX_K)), .CUTOFF((`SPECFX_CUTOFF)), .C_W((`SPECFX_C_W)),
        .C_F((`SPECFX_C_F)), .C_S((`SPECFX_C_S)), .D_W((`SPECFX_D_W)), .D_F((`SPECFX_D_F)),
        .SLOPE_W((`SPECFX_SLOPE_W)), .SLOPE_F((`SPECFX_SLOPE_F)), .SLOPE_S((`SPECFX_SLOPE_S)),
        .SLOPE_POW2((`SPECFX_SLOPE_POW2)), .OFFSET_W((`SPECFX_OFFSET_W)), .OFFSET_F((`SPECFX_OFFSET_F)),
        .OFFSET_S((`SPECFX_OFFSET_S)), .T_W((`SPECFX_T_W)), .T_F((`SPECFX_T_F)),
        .T_S((`SPECFX_T_S)), .T_RND((`SPECFX_T_RND)), .T_OVF((`SPECFX_T_OVF)), .B_W((`SPECFX_B_W)),
        .B_F((`SPECFX_B_F)), .B_S((`SPECFX_B_S)), .B_RND((`SPECFX_B_RND)), .B_OVF((`SPECFX_B_OVF)),
        .SQ1_W((`SPECFX_SQ1_W)), .SQ1_F((`SPECFX_SQ1_F)), .SQ1_S((`SPECFX_SQ1_S)),
        .SQ1_RND((`SPECFX_SQ1_RND)), .SQ1_OVF((`SPECFX_SQ1_OVF)), .SQ2_W((`SPECFX_SQ2_W)),
        .SQ2_F((`SPECFX_SQ2_F)), .SQ2_S((`SPECFX_SQ2_S)), .SQ2_RND((`SPECFX_SQ2_RND)),
        .SQ2_OVF((`SPECFX_SQ2_OVF)), .SQ3_W((`SPECFX_SQ3_W)), .SQ3_F((`SPECFX_SQ3_F)),
        .SQ3_S((`SPECFX_SQ3_S)), .SQ3_RND((`SPECFX_SQ3_RND)), .SQ3_OVF((`SPECFX_SQ3_OVF)),
        .SQ4_W((`SPECFX_SQ4_W)), .SQ4_F((`SPECFX_SQ4_F)), .SQ4_S((`SPECFX_SQ4_S)),
        .SQ4_RND((`SPECFX_SQ4_RND)), .SQ4_OVF((`SPECFX_SQ4_OVF)), .SQ5_W((`SPECFX_SQ5_W)),
        .SQ5_F((`SPECFX_SQ5_F)), .SQ5_S((`SPECFX_SQ5_S)), .SQ5_RND((`SPECFX_SQ5_RND)),
        .SQ5_OVF((`SPECFX_SQ5_OVF)), .SQ6_W((`SPECFX_SQ6_W)), .SQ6_F((`SPECFX_SQ6_F)),
        .SQ6_S((`SPECFX_SQ6_S)), .SQ6_RND((`SPECFX_SQ6_RND)), .SQ6_OVF((`SPECFX_SQ6_OVF)),
        .SQ7_W((`SPECFX_SQ7_W)), .SQ7_F((`SPECFX_SQ7_F)), .SQ7_S((`SPECFX_SQ7_S)),
        .SQ7_RND((`SPECFX_SQ7_RND)), .SQ7_OVF((`SPECFX_SQ7_OVF)), .COEF_W((`SPECFX_COEF_W)),
        .COEF_F((`SPECFX_COEF_F)), .COEF_S((`SPECFX_COEF_S)), .OUT_W((`SPECFX_OUT_W)),
        .OUT_F((`SPECFX_OUT_F)), .OUT_S((`SPECFX_OUT_S)), .OUT_RND((`SPECFX_OUT_RND)),
        .OUT_OVF((`SPECFX_OUT_OVF)), .LAT_SUB((`SPECFX_LAT_SUB)), .LAT_MUL((`SPECFX_LAT_MUL)),
        .LAT_ADD((`SPECFX_LAT_ADD)), .RESET_DATA((`SPECFX_RESET_DATA)),
        .DEPTH_MIN((`SPECFX_DEPTH_MIN))
    ) u_top (
        .clk(clk), .rst(rst),
        .in_valid(in_valid), .in_ready(in_ready),
        .in_c(in_c), .in_slope(in_slope), .in_offset(in_offset),
        .in_threshold(in_threshold), .in_coef(in_coef), .in_depth(in_depth),
        .out_valid(out_valid), .out_ready(out_ready), .out_data(out_data)
    );
endmodule

`default_nettype wire
