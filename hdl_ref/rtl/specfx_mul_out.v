// specfx_mul_out: out = Q_out(sq_k * coef) (Rust: the out stage of src/pipeline/datapath.rs
// `eval`). The last square x (X_W bits, X_F fraction bits) times the per-n coefficient (COEF_W
// bits, COEF_F fraction bits): the exact product has X_F + COEF_F fraction bits and is
// quantized to OUT with OUT_RND and OUT_OVF. Combinational.
`timescale 1ns / 1ps
`default_nettype none

module specfx_mul_out #(
    parameter integer X_W     = 17,
    parameter integer X_F     = 16,
    parameter integer X_S     = 0,
    parameter integer COEF_W  = 24,
    parameter integer COEF_F  = 16,
    parameter integer COEF_S  = 0,
    parameter integer OUT_W   = 24,
    parameter integer OUT_F   = 16,
    parameter integer OUT_S   = 0,
    parameter integer OUT_RND = 2,
    parameter integer OUT_OVF = 1
) (
    input  wire [X_W-1:0]    x,
    input  wire [COEF_W-1:0] coef,
    output wire [OUT_W-1:0]  out
);
    localparam integer P_W = X_W + COEF_W + ((X_S != 0 || COEF_S != 0) ? 0 : 1);
    wire [P_W-1:0] product;
    specfx_mul #(.A_W(X_W), .A_S(X_S), .B_W(COEF_W), .B_S(COEF_S), .P_W(P_W)) u_mul (
        .a(x), .b(coef), .p(product)
    );
    specfx_quant #(
        .IN_W(P_W), .IN_F(X_F + COEF_F), .IN_S(1),
        .OUT_W(OUT_W), .OUT_F(OUT_F), .OUT_S(OUT_S), .RND(OUT_RND), .OVF(OUT_OVF)
    ) u_q (
        .x(product), .y(out)
    );
endmodule

`default_nettype wire
