// specfx_dut: the static top of the reference RTL, with the ports of docs/cycle.md.
// Every parameter comes from specfx_params.vh (written by `specfx hdl params`); SPECFX_ARCH
// picks the microarchitecture: 0 pipelined (specfx_pipelined), 1 folded (specfx_folded).
`include "specfx_params.vh"
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
    output wire                         out_valid,
    input  wire                         out_ready,
    output wire [(`SPECFX_OUT_W)-1:0]    out_data
);
    generate
        if ((`SPECFX_ARCH) == 0) begin : g_pipelined
            specfx_pipelined #(
                .K((`SPECFX_K)), .CUTOFF((`SPECFX_CUTOFF)),
                .C_W((`SPECFX_C_W)), .C_F((`SPECFX_C_F)), .C_S((`SPECFX_C_S)),
                .D_W((`SPECFX_D_W)), .D_F((`SPECFX_D_F)),
                .SLOPE_W((`SPECFX_SLOPE_W)), .SLOPE_F((`SPECFX_SLOPE_F)), .SLOPE_S((`SPECFX_SLOPE_S)),
                .SLOPE_POW2((`SPECFX_SLOPE_POW2)),
                .OFFSET_W((`SPECFX_OFFSET_W)), .OFFSET_F((`SPECFX_OFFSET_F)), .OFFSET_S((`SPECFX_OFFSET_S)),
                .T_W((`SPECFX_T_W)), .T_F((`SPECFX_T_F)), .T_S((`SPECFX_T_S)),
                .T_RND((`SPECFX_T_RND)), .T_OVF((`SPECFX_T_OVF)),
                .B_W((`SPECFX_B_W)), .B_F((`SPECFX_B_F)), .B_S((`SPECFX_B_S)),
                .B_RND((`SPECFX_B_RND)), .B_OVF((`SPECFX_B_OVF)),
                .SQ_W((`SPECFX_SQ_W)), .SQ_F((`SPECFX_SQ_F)), .SQ_S((`SPECFX_SQ_S)),
                .SQ_RND((`SPECFX_SQ_RND)), .SQ_OVF((`SPECFX_SQ_OVF)),
                .COEF_W((`SPECFX_COEF_W)), .COEF_F((`SPECFX_COEF_F)), .COEF_S((`SPECFX_COEF_S)),
                .OUT_W((`SPECFX_OUT_W)), .OUT_F((`SPECFX_OUT_F)), .OUT_S((`SPECFX_OUT_S)),
                .OUT_RND((`SPECFX_OUT_RND)), .OUT_OVF((`SPECFX_OUT_OVF)),
                .LAT_SUB((`SPECFX_LAT_SUB)), .LAT_MUL((`SPECFX_LAT_MUL)), .LAT_ADD((`SPECFX_LAT_ADD))
            ) u_core (
                .clk(clk), .rst(rst),
                .in_valid(in_valid), .in_ready(in_ready),
                .in_c(in_c), .in_slope(in_slope), .in_offset(in_offset),
                .in_threshold(in_threshold), .in_coef(in_coef),
                .out_valid(out_valid), .out_ready(out_ready), .out_data(out_data)
            );
        end else begin : g_folded
            specfx_folded #(
                .K((`SPECFX_K)), .CUTOFF((`SPECFX_CUTOFF)),
                .C_W((`SPECFX_C_W)), .C_F((`SPECFX_C_F)), .C_S((`SPECFX_C_S)),
                .D_W((`SPECFX_D_W)), .D_F((`SPECFX_D_F)),
                .SLOPE_W((`SPECFX_SLOPE_W)), .SLOPE_F((`SPECFX_SLOPE_F)), .SLOPE_S((`SPECFX_SLOPE_S)),
                .OFFSET_W((`SPECFX_OFFSET_W)), .OFFSET_F((`SPECFX_OFFSET_F)), .OFFSET_S((`SPECFX_OFFSET_S)),
                .T_W((`SPECFX_T_W)), .T_F((`SPECFX_T_F)), .T_S((`SPECFX_T_S)),
                .T_RND((`SPECFX_T_RND)), .T_OVF((`SPECFX_T_OVF)),
                .B_W((`SPECFX_B_W)), .B_F((`SPECFX_B_F)), .B_S((`SPECFX_B_S)),
                .B_RND((`SPECFX_B_RND)), .B_OVF((`SPECFX_B_OVF)),
                .SQ_W((`SPECFX_SQ_W)), .SQ_F((`SPECFX_SQ_F)), .SQ_S((`SPECFX_SQ_S)),
                .SQ_RND((`SPECFX_SQ_RND)), .SQ_OVF((`SPECFX_SQ_OVF)),
                .COEF_W((`SPECFX_COEF_W)), .COEF_F((`SPECFX_COEF_F)), .COEF_S((`SPECFX_COEF_S)),
                .OUT_W((`SPECFX_OUT_W)), .OUT_F((`SPECFX_OUT_F)), .OUT_S((`SPECFX_OUT_S)),
                .OUT_RND((`SPECFX_OUT_RND)), .OUT_OVF((`SPECFX_OUT_OVF)),
                .LAT_MUL((`SPECFX_LAT_MUL))
            ) u_core (
                .clk(clk), .rst(rst),
                .in_valid(in_valid), .in_ready(in_ready),
                .in_c(in_c), .in_slope(in_slope), .in_offset(in_offset),
                .in_threshold(in_threshold), .in_coef(in_coef),
                .out_valid(out_valid), .out_ready(out_ready), .out_data(out_data)
            );
        end
    endgenerate
endmodule

`default_nettype wire
