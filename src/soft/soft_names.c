/*
 * libso3fft_soft: SOFT 2.0's function names, each forwarding to the libso3fft entry point that
 * implements it (exported by libso3fft as so3fft_soft_<name>, a private name declared nowhere
 * else). Keeping SOFT's names in this library leaves libso3fft's own symbols all so3fft_*, so a
 * program that links libso3fft for the native API keeps its own transpose, csecond, ...
 *
 * Each bridge is declared with the type of the SOFT header's declaration, so the compiler checks
 * every forwarder against the headers in include/soft. Compiled by CMake (cmake/soft.cmake).
 *
 * Copyright (C) the so3fft authors.
 * SPDX-License-Identifier: GPL-2.0-or-later
 */
#include <fftw3.h>

#include "csecond.h"
#include "makeWigner.h"
#include "makeweights.h"
#include "rotate_so3_fftw.h"
#include "rotate_so3_utils.h"
#include "s2_cospmls.h"
#include "s2_legendreTransforms.h"
#include "s2_primitive.h"
#include "s2_semi_fly.h"
#include "s2_semi_memo.h"
#include "so3_correlate_fftw.h"
#include "soft_fftw.h"
#include "soft_fftw_nt.h"
#include "soft_fftw_pc.h"
#include "utils_so3.h"
#include "wrap_fftw.h"

/* csecond.h */
extern __typeof__(csecond) so3fft_soft_csecond;
double csecond(void)
{
    return so3fft_soft_csecond();
}

/* makeWigner.h */
extern __typeof__(genWigAll) so3fft_soft_genWigAll;
void genWigAll(int bw, double *wigners, double *workspace)
{
    so3fft_soft_genWigAll(bw, wigners, workspace);
}
extern __typeof__(genWigAllTrans) so3fft_soft_genWigAllTrans;
void genWigAllTrans(int bw, double *wigners, double *workspace)
{
    so3fft_soft_genWigAllTrans(bw, wigners, workspace);
}

/* makeweights.h */
extern __typeof__(makeweights) so3fft_soft_makeweights;
void makeweights(int bw, double *w)
{
    so3fft_soft_makeweights(bw, w);
}
extern __typeof__(makeweights2) so3fft_soft_makeweights2;
void makeweights2(int bw, double *w)
{
    so3fft_soft_makeweights2(bw, w);
}

/* rotate_so3_fftw.h */
extern __typeof__(rotateFctFFTW) so3fft_soft_rotateFctFFTW;
void rotateFctFFTW(int bwIn, int bwOut, int degOut, double *sigInR, double *sigInI,
                   double *sigOutR, double *sigOutI, double alpha, double beta, double gamma,
                   double *scratch, double **spharmonic_pml_table,
                   double **transpose_spharmonic_pml_table)
{
    so3fft_soft_rotateFctFFTW(bwIn, bwOut, degOut, sigInR, sigInI, sigOutR, sigOutI, alpha, beta,
                              gamma, scratch, spharmonic_pml_table,
                              transpose_spharmonic_pml_table);
}
extern __typeof__(rotateFctFFTWS) so3fft_soft_rotateFctFFTWS;
void rotateFctFFTWS(int bwIn, int bwOut, int degOut, double *sigInR, double *sigInI,
                    double *sigOutR, double *sigOutI, double alpha, double beta, double gamma)
{
    so3fft_soft_rotateFctFFTWS(bwIn, bwOut, degOut, sigInR, sigInI, sigOutR, sigOutI, alpha, beta,
                               gamma);
}
extern __typeof__(rotateFctFFTWS_mem) so3fft_soft_rotateFctFFTWS_mem;
void rotateFctFFTWS_mem(int bw, int degOut, double *sigR, double *sigI, double alpha, double beta,
                        double gamma)
{
    so3fft_soft_rotateFctFFTWS_mem(bw, degOut, sigR, sigI, alpha, beta, gamma);
}

/* rotate_so3_utils.h */
extern __typeof__(rotateCoefAll) so3fft_soft_rotateCoefAll;
void rotateCoefAll(int bwIn, int bwOut, int degOut, double alpha, double beta, double gamma,
                   double *cfR, double *cfI, double *cfrR, double *cfrI, double *scratch)
{
    so3fft_soft_rotateCoefAll(bwIn, bwOut, degOut, alpha, beta, gamma, cfR, cfI, cfrR, cfrI,
                              scratch);
}

/* s2_cospmls.h */
extern __typeof__(TableSize) so3fft_soft_TableSize;
int TableSize(int m, int bw)
{
    return so3fft_soft_TableSize(m, bw);
}
extern __typeof__(Spharmonic_TableSize) so3fft_soft_Spharmonic_TableSize;
int Spharmonic_TableSize(int bw)
{
    return so3fft_soft_Spharmonic_TableSize(bw);
}
extern __typeof__(Reduced_SpharmonicTableSize) so3fft_soft_Reduced_SpharmonicTableSize;
int Reduced_SpharmonicTableSize(int bw, int m)
{
    return so3fft_soft_Reduced_SpharmonicTableSize(bw, m);
}
extern __typeof__(Reduced_Naive_TableSize) so3fft_soft_Reduced_Naive_TableSize;
int Reduced_Naive_TableSize(int bw, int m)
{
    return so3fft_soft_Reduced_Naive_TableSize(bw, m);
}
extern __typeof__(NewTableOffset) so3fft_soft_NewTableOffset;
int NewTableOffset(int m, int l)
{
    return so3fft_soft_NewTableOffset(m, l);
}
extern __typeof__(RowSize) so3fft_soft_RowSize;
int RowSize(int m, int l)
{
    return so3fft_soft_RowSize(m, l);
}
extern __typeof__(Transpose_RowSize) so3fft_soft_Transpose_RowSize;
int Transpose_RowSize(int row, int m, int bw)
{
    return so3fft_soft_Transpose_RowSize(row, m, bw);
}
extern __typeof__(PmlTableGen) so3fft_soft_PmlTableGen;
void PmlTableGen(int bw, int m, double *storeplm, double *workspace)
{
    so3fft_soft_PmlTableGen(bw, m, storeplm, workspace);
}
extern __typeof__(CosPmlTableGen) so3fft_soft_CosPmlTableGen;
void CosPmlTableGen(int bw, int m, double *tablespace, double *workspace)
{
    so3fft_soft_CosPmlTableGen(bw, m, tablespace, workspace);
}
extern __typeof__(Transpose_CosPmlTableGen) so3fft_soft_Transpose_CosPmlTableGen;
void Transpose_CosPmlTableGen(int bw, int m, double *cos_pml_table, double *result)
{
    so3fft_soft_Transpose_CosPmlTableGen(bw, m, cos_pml_table, result);
}
extern __typeof__(Spharmonic_Pml_Table) so3fft_soft_Spharmonic_Pml_Table;
double **Spharmonic_Pml_Table(int bw, double *resultspace, double *workspace)
{
    return so3fft_soft_Spharmonic_Pml_Table(bw, resultspace, workspace);
}
extern __typeof__(Transpose_Spharmonic_Pml_Table) so3fft_soft_Transpose_Spharmonic_Pml_Table;
double **Transpose_Spharmonic_Pml_Table(double **spharmonic_pml_table, int bw, double *resultspace,
                                        double *workspace)
{
    return so3fft_soft_Transpose_Spharmonic_Pml_Table(spharmonic_pml_table, bw, resultspace,
                                                      workspace);
}
extern __typeof__(SemiNaive_Naive_Pml_Table) so3fft_soft_SemiNaive_Naive_Pml_Table;
double **SemiNaive_Naive_Pml_Table(int bw, int m, double *resultspace, double *workspace)
{
    return so3fft_soft_SemiNaive_Naive_Pml_Table(bw, m, resultspace, workspace);
}
extern __typeof__(Transpose_SemiNaive_Naive_Pml_Table)
    so3fft_soft_Transpose_SemiNaive_Naive_Pml_Table;
double **Transpose_SemiNaive_Naive_Pml_Table(double **seminaive_naive_pml_table, int bw, int m,
                                             double *resultspace, double *workspace)
{
    return so3fft_soft_Transpose_SemiNaive_Naive_Pml_Table(seminaive_naive_pml_table, bw, m,
                                                           resultspace, workspace);
}

/* s2_legendreTransforms.h */
extern __typeof__(Naive_AnalysisX) so3fft_soft_Naive_AnalysisX;
void Naive_AnalysisX(double *data, int bw, int m, double *weights, double *result,
                     double *plmtable, double *workspace)
{
    so3fft_soft_Naive_AnalysisX(data, bw, m, weights, result, plmtable, workspace);
}
extern __typeof__(Naive_SynthesizeX) so3fft_soft_Naive_SynthesizeX;
void Naive_SynthesizeX(double *coeffs, int bw, int m, double *result, double *plmtable)
{
    so3fft_soft_Naive_SynthesizeX(coeffs, bw, m, result, plmtable);
}

/* s2_primitive.h */
extern __typeof__(L2_an) so3fft_soft_L2_an;
double L2_an(int m, int l)
{
    return so3fft_soft_L2_an(m, l);
}
extern __typeof__(L2_cn) so3fft_soft_L2_cn;
double L2_cn(int m, int l)
{
    return so3fft_soft_L2_cn(m, l);
}
extern __typeof__(vec_add) so3fft_soft_vec_add;
void vec_add(double *data1, double *data2, double *result, int n)
{
    so3fft_soft_vec_add(data1, data2, result, n);
}
extern __typeof__(vec_mul) so3fft_soft_vec_mul;
void vec_mul(double scalar, double *data1, double *result, int n)
{
    so3fft_soft_vec_mul(scalar, data1, result, n);
}
extern __typeof__(vec_pt_mul) so3fft_soft_vec_pt_mul;
void vec_pt_mul(double *data1, double *data2, double *result, int n)
{
    so3fft_soft_vec_pt_mul(data1, data2, result, n);
}
extern __typeof__(ArcCosEvalPts) so3fft_soft_ArcCosEvalPts;
void ArcCosEvalPts(int n, double *eval_pts)
{
    so3fft_soft_ArcCosEvalPts(n, eval_pts);
}
extern __typeof__(EvalPts) so3fft_soft_EvalPts;
void EvalPts(int n, double *eval_pts)
{
    so3fft_soft_EvalPts(n, eval_pts);
}
extern __typeof__(Pmm_L2) so3fft_soft_Pmm_L2;
void Pmm_L2(int m, double *eval_pts, int n, double *result)
{
    so3fft_soft_Pmm_L2(m, eval_pts, n, result);
}
extern __typeof__(seanindex) so3fft_soft_seanindex;
int seanindex(int m, int l, int bw)
{
    return so3fft_soft_seanindex(m, l, bw);
}
extern __typeof__(seanindex2) so3fft_soft_seanindex2;
void seanindex2(int m, int l, int bw, int *loc)
{
    so3fft_soft_seanindex2(m, l, bw, loc);
}
extern __typeof__(transpose) so3fft_soft_transpose;
void transpose(double *array, int size)
{
    so3fft_soft_transpose(array, size);
}

/* s2_semi_fly.h */
extern __typeof__(FST_semi_fly) so3fft_soft_FST_semi_fly;
void FST_semi_fly(double *rdata, double *idata, double *rcoeffs, double *icoeffs, int bw,
                  double *workspace, int dataformat, int cutoff, fftw_plan *dctPlan,
                  fftw_plan *fftPlan, double *weights)
{
    so3fft_soft_FST_semi_fly(rdata, idata, rcoeffs, icoeffs, bw, workspace, dataformat, cutoff,
                             dctPlan, fftPlan, weights);
}
extern __typeof__(InvFST_semi_fly) so3fft_soft_InvFST_semi_fly;
void InvFST_semi_fly(double *rcoeffs, double *icoeffs, double *rdata, double *idata, int bw,
                     double *workspace, int dataformat, int cutoff, fftw_plan *idctPlan,
                     fftw_plan *ifftPlan)
{
    so3fft_soft_InvFST_semi_fly(rcoeffs, icoeffs, rdata, idata, bw, workspace, dataformat, cutoff,
                                idctPlan, ifftPlan);
}

/* s2_semi_memo.h */
extern __typeof__(FST_semi_memo) so3fft_soft_FST_semi_memo;
void FST_semi_memo(double *rdata, double *idata, double *rcoeffs, double *icoeffs, int bw,
                   double **seminaive_naive_table, double *workspace, int dataformat, int cutoff,
                   fftw_plan *dctPlan, fftw_plan *fftPlan, double *weights)
{
    so3fft_soft_FST_semi_memo(rdata, idata, rcoeffs, icoeffs, bw, seminaive_naive_table, workspace,
                              dataformat, cutoff, dctPlan, fftPlan, weights);
}
extern __typeof__(InvFST_semi_memo) so3fft_soft_InvFST_semi_memo;
void InvFST_semi_memo(double *rcoeffs, double *icoeffs, double *rdata, double *idata, int bw,
                      double **transpose_seminaive_naive_table, double *workspace, int dataformat,
                      int cutoff, fftw_plan *idctPlan, fftw_plan *ifftPlan)
{
    so3fft_soft_InvFST_semi_memo(rcoeffs, icoeffs, rdata, idata, bw,
                                 transpose_seminaive_naive_table, workspace, dataformat, cutoff,
                                 idctPlan, ifftPlan);
}

/* so3_correlate_fftw.h */
extern __typeof__(so3CombineCoef_fftw) so3fft_soft_so3CombineCoef_fftw;
void so3CombineCoef_fftw(int bwIn, int bwOut, int degLim, double *sigCoefR, double *sigCoefI,
                         double *patCoefR, double *patCoefI, fftw_complex *so3Coef)
{
    so3fft_soft_so3CombineCoef_fftw(bwIn, bwOut, degLim, sigCoefR, sigCoefI, patCoefR, patCoefI,
                                    so3Coef);
}

/* soft_fftw.h */
extern __typeof__(Forward_SO3_Naive_fftw) so3fft_soft_Forward_SO3_Naive_fftw;
void Forward_SO3_Naive_fftw(int bw, fftw_complex *data, fftw_complex *coeffs,
                            fftw_complex *workspace_cx, fftw_complex *workspace_cx2,
                            double *workspace_re, double *weights, fftw_plan *p1, int flag)
{
    so3fft_soft_Forward_SO3_Naive_fftw(bw, data, coeffs, workspace_cx, workspace_cx2, workspace_re,
                                       weights, p1, flag);
}
extern __typeof__(Inverse_SO3_Naive_fftw) so3fft_soft_Inverse_SO3_Naive_fftw;
void Inverse_SO3_Naive_fftw(int bw, fftw_complex *coeffs, fftw_complex *data,
                            fftw_complex *workspace_cx, fftw_complex *workspace_cx2,
                            double *workspace_re, fftw_plan *p1, int flag)
{
    so3fft_soft_Inverse_SO3_Naive_fftw(bw, coeffs, data, workspace_cx, workspace_cx2, workspace_re,
                                       p1, flag);
}

/* soft_fftw_nt.h */
extern __typeof__(Forward_SO3_Naive_fftw_nt) so3fft_soft_Forward_SO3_Naive_fftw_nt;
void Forward_SO3_Naive_fftw_nt(int bw, fftw_complex *data, fftw_complex *coeffs,
                               fftw_complex *workspace_cx, double *workspace_re, double *weights,
                               fftw_plan *p1, int flag)
{
    so3fft_soft_Forward_SO3_Naive_fftw_nt(bw, data, coeffs, workspace_cx, workspace_re, weights,
                                          p1, flag);
}
extern __typeof__(Inverse_SO3_Naive_fftw_nt) so3fft_soft_Inverse_SO3_Naive_fftw_nt;
void Inverse_SO3_Naive_fftw_nt(int bw, fftw_complex *coeffs, fftw_complex *data,
                               fftw_complex *workspace_cx, double *workspace_re, fftw_plan *p1,
                               int flag)
{
    so3fft_soft_Inverse_SO3_Naive_fftw_nt(bw, coeffs, data, workspace_cx, workspace_re, p1, flag);
}

/* soft_fftw_pc.h */
extern __typeof__(Forward_SO3_Naive_fftw_pc) so3fft_soft_Forward_SO3_Naive_fftw_pc;
void Forward_SO3_Naive_fftw_pc(int bw, fftw_complex *data, fftw_complex *coeffs,
                               fftw_complex *workspace_cx, fftw_complex *workspace_cx2,
                               double *workspace_re, double *weights, fftw_plan *p1,
                               double *wigners, int flag)
{
    so3fft_soft_Forward_SO3_Naive_fftw_pc(bw, data, coeffs, workspace_cx, workspace_cx2,
                                          workspace_re, weights, p1, wigners, flag);
}
extern __typeof__(Inverse_SO3_Naive_fftw_pc) so3fft_soft_Inverse_SO3_Naive_fftw_pc;
void Inverse_SO3_Naive_fftw_pc(int bw, fftw_complex *coeffs, fftw_complex *data,
                               fftw_complex *workspace_cx, fftw_complex *workspace_cx2,
                               double *workspace_re, fftw_plan *p1, double *wignersTrans, int flag)
{
    so3fft_soft_Inverse_SO3_Naive_fftw_pc(bw, coeffs, data, workspace_cx, workspace_cx2,
                                          workspace_re, p1, wignersTrans, flag);
}

/* utils_so3.h */
extern __typeof__(totalCoeffs_so3) so3fft_soft_totalCoeffs_so3;
int totalCoeffs_so3(int bw)
{
    return so3fft_soft_totalCoeffs_so3(bw);
}
extern __typeof__(numCoeffs_so3) so3fft_soft_numCoeffs_so3;
int numCoeffs_so3(int bw, int m1)
{
    return so3fft_soft_numCoeffs_so3(bw, m1);
}
extern __typeof__(howMany_so3) so3fft_soft_howMany_so3;
int howMany_so3(int m1, int m2, int bw)
{
    return so3fft_soft_howMany_so3(m1, m2, bw);
}
extern __typeof__(sampLoc_so3) so3fft_soft_sampLoc_so3;
int sampLoc_so3(int m1, int m2, int bw)
{
    return so3fft_soft_sampLoc_so3(m1, m2, bw);
}
extern __typeof__(coefLoc_so3) so3fft_soft_coefLoc_so3;
int coefLoc_so3(int m1, int m2, int bw)
{
    return so3fft_soft_coefLoc_so3(m1, m2, bw);
}
extern __typeof__(so3CoefLoc) so3fft_soft_so3CoefLoc;
int so3CoefLoc(int m, int mp, int l, int bw)
{
    return so3fft_soft_so3CoefLoc(m, mp, l, bw);
}

/* wrap_fftw.h */
extern __typeof__(Forward_SO3_Naive_fftw_W) so3fft_soft_Forward_SO3_Naive_fftw_W;
void Forward_SO3_Naive_fftw_W(int bw, fftw_complex *signal, fftw_complex *coeffs, int flag)
{
    so3fft_soft_Forward_SO3_Naive_fftw_W(bw, signal, coeffs, flag);
}
extern __typeof__(Inverse_SO3_Naive_fftw_W) so3fft_soft_Inverse_SO3_Naive_fftw_W;
void Inverse_SO3_Naive_fftw_W(int bw, fftw_complex *coeffs, fftw_complex *signal, int flag)
{
    so3fft_soft_Inverse_SO3_Naive_fftw_W(bw, coeffs, signal, flag);
}
extern __typeof__(softFFTWCor2) so3fft_soft_softFFTWCor2;
void softFFTWCor2(int bw, double *sig, double *pat, double *alpha, double *beta, double *gamma,
                  int isReal)
{
    so3fft_soft_softFFTWCor2(bw, sig, pat, alpha, beta, gamma, isReal);
}
extern __typeof__(s2RotateFFTW) so3fft_soft_s2RotateFFTW;
void s2RotateFFTW(int bw, double *sigIn, double *sigOut, double alpha, double beta, double gamma,
                  int isReal)
{
    so3fft_soft_s2RotateFFTW(bw, sigIn, sigOut, alpha, beta, gamma, isReal);
}
