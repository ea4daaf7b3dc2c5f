// specfx_square: sq_i = Q_i(sq_{i-1}^2), one squaring of the power chain (Rust: the square
// stages of src/pipeline/datapath.rs `eval`; sq_0 = b). The input x has X_W bits, X_F fraction
// bits; the exact square has 2 X_F fraction bits (e.g. u1.16 x u1.16 -> u2.32) and is
// quantized to Y with Y_RND and Y_OVF. With BYPASS = 1, `pass` high requantizes x itself
// instead (a bypassed stage of a per-n depth; specfx_sq_quant). Combinational.
`timescale 1ns / 1ps
`default_nettype none

module specfx_square #(
    parameter integer X_W   = 17,
    parameter integer X_F   = 16,
    parameter integer X_S   = 0,
    parameter integer Y_W   = 17,
    parameter integer Y_F   = 16,
    parameter integer Y_S   = 0,
    parameter integer Y_RND = 2,
    parameter integer Y_OVF = 1,
    parameter integer BYPASS = 0
) (
    input  wire [X_W-1:0] x,
    input  wire           pass,
    output wire [Y_W-1:0] y
);
    localparam integer P_W = 2 * X_W + ((X_S != 0) ? 0 : 1);
    wire [P_W-1:0] product;
    specfx_mul #(.A_W(X_W), .A_S(X_S), .B_W(X_W), .B_S(X_S), .P_W(P_W)) u_mul (
        .a(x), .b(x), .p(product)
    );
    specfx_sq_quant #(
        .P_W(P_W), .X_W(X_W), .X_F(X_F), .X_S(X_S),
        .Y_W(Y_W), .Y_F(Y_F), .Y_S(Y_S), .Y_RND(Y_RND), .Y_OVF(Y_OVF), .BYPASS(BYPASS)
    ) u_q (
        .product(product), .x(x), .pass(pass), .y(y)
    );
endmodule

`default_nettype wire
