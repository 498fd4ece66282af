/*
 * amfi-formulations: the alternative output equations of MODEL.md §4
 * measured against the paper formulation on the same data (the Newmark
 * response of prescribed moving forces): per-axle and GVW error, and the fit
 * residual relative to the signal. Prints one line per case × formulation × λ.
 */
#include <stdio.h>
#include <stdlib.h>
#include <math.h>
#include "amfi/amfi.h"
typedef struct { double F[2]; double amp, f; } fdat;
static double force(double t, int a, void *u)
{
    fdat *d = u;
    return d->F[a]*(1+d->amp*sin(2*M_PI*d->f*t+1.3*a)); }
int main(void)
{
  amfi_set_blas_threads(1);
  amfi_bridge_params bp; amfi_bridge_params_paper20(&bp); amfi_bridge *b; amfi_bridge_create(&bp,&b,0,0);
  double v=25, off[2]={0,5}, xs[3]={10,5,15};
  struct {double amp; int ns; double rate;} cs[]={{0,1,5000},{0,1,1000},{0,1,500},{0.1,3,5000},{0.1,3,1000}};
  double lams[]={7.94e-9,1e-12};
  for(int c=0;c<5;c++){ fdat fd={{102000,74600},cs[c].amp,2}; int ns=cs[c].ns; double rate=cs[c].rate; int nout=(int)(1.1*rate)+1;
    double *acc=malloc(sizeof(double)*nout*ns); amfi_forward_newmark(b,v,2,off,force,&fd,ns,xs,2e-5,rate,nout,acc,0,0);
    double *ac[3]; for(int s=0;s<ns;s++){ac[s]=malloc(sizeof(double)*nout); for(int i=0;i<nout;i++) ac[s][i]=acc[i*ns+s];}
    for(int f=0;f<3;f++) for(int li=0;li<2;li++){
      amfi_solver_params sp; amfi_solver_params_default(&sp,20); sp.formulation=f; sp.n_sensors=ns; for(int s=0;s<ns;s++){sp.sensor_x_m[s]=xs[s];sp.sensor_weight[s]=1;}
      amfi_solver *s; char err[200]; if(amfi_solver_create(b,&sp,&s,err,200)){puts(err);return 1;}
      amfi_passage p={0}; p.n_samples=nout; p.scan_rate_hz=rate; for(int q=0;q<ns;q++) p.accel[q]=ac[q]; p.speed_mps=v; p.n_axles=2; p.axle_spacing_m[0]=5;
      amfi_lambda lam; amfi_lambda_default(&lam); lam.lambda_ref=lams[li]; amfi_result r; if(amfi_solve(s,&p,&lam,&r,err,200)){puts(err);return 1;}
      double tm[2]; for(int a=0;a<2;a++){double sum=0;int n=0; for(int j=0;j<=r.n_steps;j++){double t=r.t0_s+j*r.h_s,x=v*t-off[a]; if(x<0||x>20)continue; sum+=force(t,a,&fd);n++;} tm[a]=sum/n;}
      printf("amp %.1f ns %d data %4.0f  %-8s lam %.2g: axle %+7.3f%% %+7.3f%%  GVW %+7.3f%%  resid/signal %.4f\n", cs[c].amp, ns, rate, amfi_formulation_name(f), lams[li],
        100*(r.mean_force_N[0]/tm[0]-1),100*(r.mean_force_N[1]/tm[1]-1),100*((r.mean_force_N[0]+r.mean_force_N[1])/(tm[0]+tm[1])-1), r.residual_rms/r.signal_rms);
      amfi_solver_destroy(s);}
  }
}
