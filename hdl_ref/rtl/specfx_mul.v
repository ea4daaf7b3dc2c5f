// specfx_mul: the product of two raw codes, a * b, as a signed P_W-bit code (no rounding, no
// overflow). It is exact when P_W holds the exact product: A_W + B_W bits when either operand
// is signed, A_W + B_W + 1 when both are unsigned (the stage modules); with a smaller P_W it is
// the low P_W bits of the product (specfx_folded, where each step reads only the bits of its
// own exact product). The fraction bits of the product are the sum of the operands' (the
// caller knows them). Rust: the `i128` products of src/pipeline/datapath.rs `eval`.
`timescale 1ns / 1ps
`default_nettype none

module specfx_mul #(
    parameter integer A_W = 8,
    parameter integer A_S = 1,
    parameter integer B_W = 8,
    parameter integer B_S = 1,
    parameter integer P_W = 16
) (
    input  wire [A_W-1:0] a,
    input  wire [B_W-1:0] b,
    output wire [P_W-1:0] p
);
    // Both operands as signed values one bit wider, then a signed multiply in M_W bits: P_W,
    // or the wider operand's width when P_W is narrower (specfx_folded, a one-bit factor
    // beside a wide operand). Its low P_W bits are the same either way.
    localparam integer AB_W = ((A_W > B_W) ? A_W : B_W) + 1;
    localparam integer M_W = (P_W > AB_W) ? P_W : AB_W;
    wire signed [A_W:0] a_x = {(A_S != 0) & a[A_W-1], a};
    wire signed [B_W:0] b_x = {(B_S != 0) & b[B_W-1], b};
    wire signed [M_W-1:0] product = a_x * b_x;
    assign p = product[P_W-1:0];
    generate
        if (M_W > P_W) begin : g_unused
            wire _unused_ok = &{1'b0, product[M_W-1:P_W]};
        end
    endgenerate
endmodule

`default_nettype wire
